//! The CARMEN log reader (format and conventions in the module doc). Every field is looked up
//! with `get` and every count is checked against the fields present before anything is
//! allocated, so no input can make it panic.

use super::fields::{Fields, parse_f64};
use super::{CarmenError, CarmenLog, OdomRecord, RobotLaserInfo, ScanRecord, ScanSource};
use super::{Pose2, TruePosRecord};
use std::f64::consts::PI;
use std::path::Path;
use systems::core::input::{MAX_DATA_BYTES, read_bounded};

/// Geometry for old `FLASER`/`RLASER` lines, overriding the log's PARAMs. SI units.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OldLaserOverrides {
    /// Field of view (rad).
    pub fov: Option<f64>,
    /// Angle between beams (rad).
    pub resolution: Option<f64>,
    /// Maximum range (m).
    pub max_range: Option<f64>,
}

/// Reader options: geometry overrides for the old front (`FLASER`) and rear (`RLASER`) lines.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CarmenReadOptions {
    pub front: OldLaserOverrides,
    pub rear: OldLaserOverrides,
}

const PARAM_FORMAT: &str = "PARAM param_name param_value";
const ODOM_FORMAT: &str = "ODOM x y theta tv rv accel timestamp hostname logger_timestamp";
const TRUEPOS_FORMAT: &str = "TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta \
                              timestamp hostname logger_timestamp";
const OLD_TAIL: &str = "x y theta odom_x odom_y odom_theta timestamp hostname logger_timestamp";
const FLASER_FORMAT: &str = "FLASER num_readings [range_readings] x y theta odom_x odom_y \
                             odom_theta timestamp hostname logger_timestamp";
const RLASER_FORMAT: &str = "RLASER num_readings [range_readings] x y theta odom_x odom_y \
                             odom_theta timestamp hostname logger_timestamp";
const NEW_TAIL: &str = "laser_pose_x laser_pose_y laser_pose_theta robot_pose_x robot_pose_y \
                        robot_pose_theta laser_tv laser_rv forward_safety_dist \
                        side_safety_dist turn_axis timestamp hostname logger_timestamp";
const ROBOTLASER1_FORMAT: &str = "ROBOTLASER1 laser_type start_angle field_of_view \
    angular_resolution maximum_range accuracy remission_mode num_readings [range_readings] \
    num_remissions [remission_values] laser_pose_x laser_pose_y laser_pose_theta robot_pose_x \
    robot_pose_y robot_pose_theta laser_tv laser_rv forward_safety_dist side_safety_dist \
    turn_axis timestamp hostname logger_timestamp";
const ROBOTLASER2_FORMAT: &str = "ROBOTLASER2 laser_type start_angle field_of_view \
    angular_resolution maximum_range accuracy remission_mode num_readings [range_readings] \
    num_remissions [remission_values] laser_pose_x laser_pose_y laser_pose_theta robot_pose_x \
    robot_pose_y robot_pose_theta laser_tv laser_rv forward_safety_dist side_safety_dist \
    turn_axis timestamp hostname logger_timestamp";

/// Reads a CARMEN log file. Gzip-compressed logs are refused with a clear error (decompress
/// them first); bytes that are not UTF-8 are replaced, which only matters inside skipped lines.
pub fn read_carmen(path: &Path, opts: &CarmenReadOptions) -> Result<CarmenLog, CarmenError> {
    let file = path.display().to_string();
    let bytes = read_bounded(path, MAX_DATA_BYTES).map_err(|error| CarmenError::Io {
        file: file.clone(),
        error,
    })?;
    if bytes.starts_with(&[0x1f, 0x8b]) {
        return Err(CarmenError::NotText {
            file,
            message: "gzip-compressed; expected a plain-text CARMEN log (gunzip it first)".into(),
        });
    }
    parse_carmen(&String::from_utf8_lossy(&bytes), &file, opts)
}

/// Parses the text of a CARMEN log; `name` is the file name errors give. Lines are parsed on
/// their own (a large log in parallel, in contiguous runs of lines) and applied in order, so the
/// log and the first error are the same as line by line.
pub fn parse_carmen(
    text: &str,
    name: &str,
    opts: &CarmenReadOptions,
) -> Result<CarmenLog, CarmenError> {
    let threads = if text.len() < PARALLEL_BYTES {
        1
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get().min(MAX_PARSE_THREADS))
    };
    parse_on(text, name, opts, threads)
}

/// [`parse_carmen`] on `threads` threads.
fn parse_on(
    text: &str,
    name: &str,
    opts: &CarmenReadOptions,
    threads: usize,
) -> Result<CarmenLog, CarmenError> {
    check_options("front", &opts.front)?;
    check_options("rear", &opts.rear)?;
    let mut p = Parser {
        front: LaserParams::default(),
        rear: LaserParams::default(),
        log: CarmenLog::default(),
        old_front: Vec::new(),
        old_rear: Vec::new(),
    };
    let lines: Vec<&str> = text.lines().collect();
    let items = parse_lines(&lines, name, threads);
    for item in items {
        match item? {
            Line::Blank => {}
            Line::Param(line) => {
                let raw = lines[line - 1];
                let mut toks = raw.split_whitespace();
                toks.next();
                p.param(Fields {
                    file: name,
                    line,
                    message: "PARAM",
                    format: PARAM_FORMAT,
                    toks: toks.collect(),
                    pos: 0,
                })?;
            }
            Line::Odom(r) => p.log.odometry.push(r),
            Line::Truth(r) => p.log.truth.push(r),
            Line::OldFront(s) => p.old_front.push(s),
            Line::OldRear(s) => p.old_rear.push(s),
            Line::Front(s) => p.log.scans.push(s),
            Line::Rear(s) => p.log.rear_scans.push(s),
            Line::Skipped(kind) => *p.log.skipped.entry(kind.to_string()).or_default() += 1,
        }
    }
    Ok(p.finish(opts))
}

/// Logs from this size on are parsed on several threads.
const PARALLEL_BYTES: usize = 1 << 20;
const MAX_PARSE_THREADS: usize = 8;

/// One line, parsed on its own. PARAM lines change the reader's state, so they are only
/// noted here (by line number) and read in order.
enum Line<'a> {
    Blank,
    Param(usize),
    Odom(OdomRecord),
    Truth(TruePosRecord),
    OldFront(ScanRecord),
    OldRear(ScanRecord),
    Front(ScanRecord),
    Rear(ScanRecord),
    Skipped(&'a str),
}

/// Every line parsed, in order, in `threads` contiguous runs.
fn parse_lines<'a>(
    lines: &[&'a str],
    name: &str,
    threads: usize,
) -> Vec<Result<Line<'a>, CarmenError>> {
    if threads <= 1 {
        return lines
            .iter()
            .enumerate()
            .map(|(i, raw)| parse_line(i + 1, raw, name))
            .collect();
    }
    let run = lines.len().div_ceil(threads).max(1);
    let parts: Option<Vec<Vec<_>>> = std::thread::scope(|scope| {
        let handles: Vec<_> = lines
            .chunks(run)
            .enumerate()
            .map(|(k, chunk)| {
                std::thread::Builder::new()
                    .spawn_scoped(scope, move || {
                        chunk
                            .iter()
                            .enumerate()
                            .map(|(i, raw)| parse_line(k * run + i + 1, raw, name))
                            .collect::<Vec<_>>()
                    })
                    .ok()
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.and_then(|h| h.join().ok()))
            .collect()
    });
    match parts {
        Some(parts) => parts.into_iter().flatten().collect(),
        // a thread that could not start (parsing itself does not panic): all on this one
        None => parse_lines(lines, name, 1),
    }
}

/// Line `line` (1-based) of the log.
fn parse_line<'a>(line: usize, raw: &'a str, name: &str) -> Result<Line<'a>, CarmenError> {
    let mut toks = raw.split_whitespace();
    let Some(kind) = toks.next() else {
        return Ok(Line::Blank);
    };
    if kind.starts_with('#') {
        return Ok(Line::Blank);
    }
    let fields = |message, format| Fields {
        file: name,
        line,
        message,
        format,
        toks: toks.clone().collect(),
        pos: 0,
    };
    Ok(match kind {
        "PARAM" => Line::Param(line),
        "ODOM" => Line::Odom(odom(fields("ODOM", ODOM_FORMAT))?),
        "TRUEPOS" => Line::Truth(truepos(fields("TRUEPOS", TRUEPOS_FORMAT))?),
        "FLASER" => Line::OldFront(old_laser(
            fields("FLASER", FLASER_FORMAT),
            ScanSource::Flaser,
        )?),
        "RLASER" => Line::OldRear(old_laser(
            fields("RLASER", RLASER_FORMAT),
            ScanSource::Rlaser,
        )?),
        "ROBOTLASER1" => Line::Front(robot_laser(
            fields("ROBOTLASER1", ROBOTLASER1_FORMAT),
            ScanSource::RobotLaser1,
        )?),
        "ROBOTLASER2" => Line::Rear(robot_laser(
            fields("ROBOTLASER2", ROBOTLASER2_FORMAT),
            ScanSource::RobotLaser2,
        )?),
        other => Line::Skipped(other),
    })
}

fn check_options(side: &str, o: &OldLaserOverrides) -> Result<(), CarmenError> {
    let checks = [
        ("fov", o.fov, "a field of view in (0, 2π] rad"),
        ("resolution", o.resolution, "a positive angle (rad)"),
        ("max_range", o.max_range, "a positive range (m)"),
    ];
    for (name, value, expected) in checks {
        let Some(v) = value else { continue };
        let bad = !(v.is_finite() && v > 0.0) || (name == "fov" && v > 2.0 * PI + 1e-9);
        if bad {
            return Err(CarmenError::BadOption {
                name: format!("{side}.{name}"),
                expected: expected.into(),
                value: v,
            });
        }
    }
    Ok(())
}

/// The laser PARAMs the reader honours, for one laser (module doc lists the names).
#[derive(Default)]
struct LaserParams {
    offset: Option<f64>,
    side_offset: Option<f64>,
    angular_offset: Option<f64>,
    fov_deg: Option<f64>,
    resolution_deg: Option<f64>,
    max_range: Option<f64>,
}

impl LaserParams {
    fn mount(&self) -> Option<Pose2> {
        if self.offset.is_none() && self.side_offset.is_none() && self.angular_offset.is_none() {
            return None;
        }
        Some(Pose2::new(
            self.offset.unwrap_or(0.0),
            self.side_offset.unwrap_or(0.0),
            self.angular_offset.unwrap_or(0.0),
        ))
    }

    /// Completes an old line's geometry: options, then PARAMs, then CARMEN's guess.
    fn apply(&self, o: &OldLaserOverrides, s: &mut ScanRecord) {
        let n = s.ranges.len();
        // CARMEN's readlog guesses (carmen_laser_guess_fov / _angle_increment): SICK LMS
        // settings by beam count, an even count meaning the last beam was dropped.
        let table = match n {
            180 | 181 => Some((PI, PI / 180.0)),
            360 | 361 => Some((PI, PI / 360.0)),
            400 | 401 => Some((100f64.to_radians(), PI / 720.0)),
            _ => None,
        };
        let guessed_fov = table.map_or(PI, |t| t.0);
        let fov = o
            .fov
            .or(self.fov_deg.map(f64::to_radians))
            .unwrap_or(guessed_fov);
        let resolution = o.resolution.or(self.resolution_deg.map(f64::to_radians));
        s.angle_increment = match (resolution, table) {
            (Some(r), _) => r,
            (None, Some((tf, tr))) if (tf - fov).abs() < 1e-9 => tr,
            (None, _) if n > 1 => fov / (n - 1) as f64,
            (None, _) => 0.0,
        };
        s.fov = fov;
        s.start_angle = -fov / 2.0;
        s.max_range = o.max_range.or(self.max_range).unwrap_or(80.0);
    }
}

struct Parser {
    front: LaserParams,
    rear: LaserParams,
    log: CarmenLog,
    old_front: Vec<ScanRecord>,
    old_rear: Vec<ScanRecord>,
}

impl Parser {
    fn param(&mut self, mut f: Fields) -> Result<(), CarmenError> {
        let name = f.next("param_name")?;
        let value = f.next("param_value")?;
        // (slot, must be positive, unit)
        let honoured = match name {
            "robot_frontlaser_offset" => Some((&mut self.front.offset, false, "m")),
            "robot_frontlaser_side_offset" => Some((&mut self.front.side_offset, false, "m")),
            "robot_frontlaser_angular_offset" => {
                Some((&mut self.front.angular_offset, false, "rad"))
            }
            "laser_front_laser_fov" => Some((&mut self.front.fov_deg, true, "degrees")),
            "laser_front_laser_resolution" => {
                Some((&mut self.front.resolution_deg, true, "degrees"))
            }
            "robot_front_laser_max" => Some((&mut self.front.max_range, true, "m")),
            "robot_rearlaser_offset" => Some((&mut self.rear.offset, false, "m")),
            "robot_rearlaser_side_offset" => Some((&mut self.rear.side_offset, false, "m")),
            "robot_rearlaser_angular_offset" => Some((&mut self.rear.angular_offset, false, "rad")),
            "laser_rear_laser_fov" => Some((&mut self.rear.fov_deg, true, "degrees")),
            "laser_rear_laser_resolution" => Some((&mut self.rear.resolution_deg, true, "degrees")),
            "robot_rear_laser_max" => Some((&mut self.rear.max_range, true, "m")),
            _ => None,
        };
        if let Some((slot, positive, unit)) = honoured {
            let v = parse_f64(value).filter(|v| !positive || *v > 0.0);
            let Some(v) = v else {
                let sign = if positive { "positive" } else { "finite" };
                return Err(f.bad(name, &format!("a {sign} number ({unit})"), value));
            };
            *slot = Some(v);
        }
        self.log.params.insert(name.to_string(), value.to_string());
        Ok(())
    }

    fn finish(mut self, opts: &CarmenReadOptions) -> CarmenLog {
        for s in &mut self.old_front {
            self.front.apply(&opts.front, s);
        }
        for s in &mut self.old_rear {
            self.rear.apply(&opts.rear, s);
        }
        let log = &mut self.log;
        for (kept, old, name) in [
            (&mut log.scans, self.old_front, "FLASER"),
            (&mut log.rear_scans, self.old_rear, "RLASER"),
        ] {
            if kept.is_empty() {
                *kept = old;
            } else if !old.is_empty() {
                *log.skipped.entry(name.to_string()).or_default() += old.len();
            }
        }
        for (scans, params) in [
            (&mut log.scans, &self.front),
            (&mut log.rear_scans, &self.rear),
        ] {
            if let Some(m) = params.mount() {
                scans.iter_mut().for_each(|s| s.mount = m);
            }
        }
        self.log
    }
}

fn odom(mut f: Fields) -> Result<OdomRecord, CarmenError> {
    let pose = f.pose(["x", "y", "theta"])?;
    let tv = f.num("tv")?;
    let rv = f.num("rv")?;
    let accel = f.num("accel")?;
    let timestamp = f.trailer()?;
    f.end()?;
    Ok(OdomRecord {
        timestamp,
        pose,
        tv,
        rv,
        accel,
    })
}

fn truepos(mut f: Fields) -> Result<TruePosRecord, CarmenError> {
    let truth = f.pose(["true_x", "true_y", "true_theta"])?;
    let odom = f.pose(["odom_x", "odom_y", "odom_theta"])?;
    let timestamp = f.trailer()?;
    f.end()?;
    Ok(TruePosRecord {
        timestamp,
        truth,
        odom,
    })
}

/// `laser` in the frame of `robot` (`robot⁻¹ ⊕ laser`), from the differences, so equal poses
/// give exactly the identity.
fn relative(robot: &Pose2, laser: &Pose2) -> Pose2 {
    let (s, c) = robot.theta.sin_cos();
    let (dx, dy) = (laser.x - robot.x, laser.y - robot.y);
    Pose2::new(c * dx + s * dy, -s * dx + c * dy, laser.theta - robot.theta)
}

/// `FLASER`/`RLASER`; geometry is filled in by [`LaserParams::apply`] once all PARAMs are known.
fn old_laser(mut f: Fields, source: ScanSource) -> Result<ScanRecord, CarmenError> {
    let n = f.count("num_readings")?;
    let rem = f.remaining();
    if n.checked_add(9) != Some(rem) {
        let hint = format!(
            "num_readings is {n}; the readings are followed by 9 fields `{OLD_TAIL}`; \
             the line has {rem} fields after num_readings"
        );
        return Err(f.count_mismatch("range readings", n, rem.saturating_sub(9), hint));
    }
    let ranges = f.ranges(n)?;
    let laser_pose = f.pose(["x", "y", "theta"])?;
    let robot_pose = f.pose(["odom_x", "odom_y", "odom_theta"])?;
    let timestamp = f.trailer()?;
    f.end()?;
    Ok(ScanRecord {
        timestamp,
        source,
        ranges,
        laser_pose,
        robot_pose,
        mount: relative(&robot_pose, &laser_pose),
        ..ScanRecord::default()
    })
}

fn robot_laser(mut f: Fields, source: ScanSource) -> Result<ScanRecord, CarmenError> {
    let laser_type = f.int("laser_type")?;
    let start_angle = f.num("start_angle")?;
    let fov = f.num("field_of_view")?;
    let angle_increment = f.num("angular_resolution")?;
    let max_range = f.num("maximum_range")?;
    if max_range <= 0.0 {
        return Err(f.bad_prev("maximum_range", "a positive range (m)"));
    }
    let accuracy = f.num("accuracy")?;
    let remission_mode = f.int("remission_mode")?;
    let n = f.count("num_readings")?;
    let rem = f.remaining();
    if n.checked_add(15).is_none_or(|need| rem < need) {
        let hint = format!(
            "num_readings is {n}; the readings are followed by num_remissions, the remission \
             values and 14 fields `{NEW_TAIL}`; the line has {rem} fields after num_readings"
        );
        return Err(f.count_mismatch("range readings", n, rem.saturating_sub(15), hint));
    }
    let ranges = f.ranges(n)?;
    let m = f.count("num_remissions")?;
    let rem = f.remaining();
    if m.checked_add(14) != Some(rem) {
        let hint = format!(
            "num_remissions is {m} (after {n} range readings); the remission values are \
             followed by 14 fields `{NEW_TAIL}`; the line has {rem} fields after num_remissions"
        );
        return Err(f.count_mismatch("remission values", m, rem.saturating_sub(14), hint));
    }
    let remissions = f.remissions(m)?;
    let laser_pose = f.pose(["laser_pose_x", "laser_pose_y", "laser_pose_theta"])?;
    let robot_pose = f.pose(["robot_pose_x", "robot_pose_y", "robot_pose_theta"])?;
    let info = RobotLaserInfo {
        laser_type,
        accuracy,
        remission_mode,
        laser_tv: f.num("laser_tv")?,
        laser_rv: f.num("laser_rv")?,
        forward_safety_dist: f.num("forward_safety_dist")?,
        side_safety_dist: f.num("side_safety_dist")?,
        turn_axis: f.num("turn_axis")?,
    };
    let timestamp = f.trailer()?;
    f.end()?;
    Ok(ScanRecord {
        timestamp,
        source,
        ranges,
        start_angle,
        angle_increment,
        fov,
        max_range,
        laser_pose,
        robot_pose,
        mount: relative(&robot_pose, &laser_pose),
        remissions,
        info,
    })
}

#[cfg(test)]
mod tests;
