//! The CARMEN log writer (what it writes is in the module doc). Numbers use Rust's `Display`,
//! the shortest text that parses back to the same f64/f32, so write → read is exact.

use super::{CarmenError, CarmenEvent, CarmenLog, OdomRecord, ScanRecord, TruePosRecord};
use std::collections::BTreeMap;
use std::io::{self, Write};
use std::path::Path;

/// Writer options.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CarmenWriteOptions {
    /// Also write every scan as an old `FLASER`/`RLASER` line (after its `ROBOTLASER` line),
    /// for tools that read only those. Our reader then keeps the `ROBOTLASER` lines.
    pub old_laser_lines: bool,
}

const HOST: &str = "sim";

/// Writes `log` as a CARMEN log with `ROBOTLASER` lines only.
pub fn write_carmen(w: &mut impl Write, log: &CarmenLog) -> io::Result<()> {
    write_carmen_with(w, log, &CarmenWriteOptions::default())
}

/// Writes `log` to the file `path`; errors name the file.
pub fn save_carmen(
    path: &Path,
    log: &CarmenLog,
    opts: &CarmenWriteOptions,
) -> Result<(), CarmenError> {
    let io_err = |error| CarmenError::Write {
        file: path.display().to_string(),
        error,
    };
    let file = std::fs::File::create(path).map_err(io_err)?;
    let mut w = io::BufWriter::new(file);
    write_carmen_with(&mut w, log, opts).map_err(io_err)?;
    w.flush().map_err(io_err)
}

/// Writes `log` as a CARMEN log: header, PARAMs, then records in timestamp order.
pub fn write_carmen_with(
    w: &mut impl Write,
    log: &CarmenLog,
    opts: &CarmenWriteOptions,
) -> io::Result<()> {
    write_header(w, opts)?;
    for (name, value) in params_to_write(log) {
        let plain = |s: &str| !s.is_empty() && !s.contains(char::is_whitespace);
        if !plain(&name) || !plain(&value) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("PARAM `{name}` = `{value}`: names and values must be one word each"),
            ));
        }
        writeln!(w, "PARAM {name} {value} 0 {HOST} 0")?;
    }
    for event in log.events() {
        match event {
            CarmenEvent::Odometry(o) => write_odom(w, o)?,
            CarmenEvent::Truth(t) => write_truepos(w, t)?,
            CarmenEvent::Scan(s) => {
                write_robot_laser(w, "ROBOTLASER1", s)?;
                if opts.old_laser_lines {
                    write_old_laser(w, "FLASER", s)?;
                }
            }
            CarmenEvent::RearScan(s) => {
                write_robot_laser(w, "ROBOTLASER2", s)?;
                if opts.old_laser_lines {
                    write_old_laser(w, "RLASER", s)?;
                }
            }
        }
    }
    Ok(())
}

fn write_header(w: &mut impl Write, opts: &CarmenWriteOptions) -> io::Result<()> {
    let old = if opts.old_laser_lines {
        "\n# old message formats defined: FLASER RLASER\
         \n# FLASER num_readings [range_readings] x y theta odom_x odom_y odom_theta\
         \n# RLASER num_readings [range_readings] x y theta odom_x odom_y odom_theta"
    } else {
        ""
    };
    writeln!(
        w,
        "# CARMEN Logfile\n\
         # written by sim\n\
         # file format is one message per line\n\
         # message_name [message contents] ipc_timestamp ipc_hostname logger_timestamp\n\
         # message formats defined: PARAM ODOM TRUEPOS ROBOTLASER1 ROBOTLASER2\n\
         # PARAM param_name param_value\n\
         # ODOM x y theta tv rv accel\n\
         # TRUEPOS true_x true_y true_theta odom_x odom_y odom_theta\n\
         # ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range \
         accuracy remission_mode num_readings [range_readings] num_remissions [remission values] \
         laser_pose_x laser_pose_y laser_pose_theta robot_pose_x robot_pose_y robot_pose_theta \
         laser_tv laser_rv forward_safety_dist side_safty_dist turn_axis\n\
         # ROBOTLASER2 as ROBOTLASER1, rear laser{old}"
    )
}

/// The log's PARAMs plus, where missing, the laser ones derived from the first scan of each
/// laser, so old lines and other tools get the geometry and the mounting.
fn params_to_write(log: &CarmenLog) -> BTreeMap<String, String> {
    let mut out = log.params.clone();
    for (scans, robot, laser) in [
        (&log.scans, "front", "front"),
        (&log.rear_scans, "rear", "rear"),
    ] {
        let Some(s) = scans.first() else { continue };
        let derived = [
            (format!("robot_{robot}laser_offset"), s.mount.x),
            (format!("robot_{robot}laser_side_offset"), s.mount.y),
            (format!("robot_{robot}laser_angular_offset"), s.mount.theta),
            (format!("laser_{laser}_laser_fov"), s.fov.to_degrees()),
            (
                format!("laser_{laser}_laser_resolution"),
                s.angle_increment.to_degrees(),
            ),
            (format!("robot_{robot}_laser_max"), s.max_range),
        ];
        for (name, value) in derived {
            out.entry(name).or_insert_with(|| value.to_string());
        }
    }
    out
}

fn write_odom(w: &mut impl Write, o: &OdomRecord) -> io::Result<()> {
    let p = &o.pose;
    let t = o.timestamp;
    writeln!(
        w,
        "ODOM {} {} {} {} {} {} {t} {HOST} {t}",
        p.x, p.y, p.theta, o.tv, o.rv, o.accel
    )
}

fn write_truepos(w: &mut impl Write, r: &TruePosRecord) -> io::Result<()> {
    let (a, b) = (&r.truth, &r.odom);
    let t = r.timestamp;
    writeln!(
        w,
        "TRUEPOS {} {} {} {} {} {} {t} {HOST} {t}",
        a.x, a.y, a.theta, b.x, b.y, b.theta
    )
}

fn write_values(w: &mut impl Write, values: &[f32]) -> io::Result<()> {
    write!(w, " {}", values.len())?;
    for v in values {
        write!(w, " {v}")?;
    }
    Ok(())
}

fn write_robot_laser(w: &mut impl Write, name: &str, s: &ScanRecord) -> io::Result<()> {
    let i = &s.info;
    write!(
        w,
        "{name} {} {} {} {} {} {} {}",
        i.laser_type,
        s.start_angle,
        s.fov,
        s.angle_increment,
        s.max_range,
        i.accuracy,
        i.remission_mode
    )?;
    write_values(w, &s.ranges)?;
    write_values(w, &s.remissions)?;
    let (l, r) = (&s.laser_pose, &s.robot_pose);
    let t = s.timestamp;
    writeln!(
        w,
        " {} {} {} {} {} {} {} {} {} {} {} {t} {HOST} {t}",
        l.x,
        l.y,
        l.theta,
        r.x,
        r.y,
        r.theta,
        i.laser_tv,
        i.laser_rv,
        i.forward_safety_dist,
        i.side_safety_dist,
        i.turn_axis
    )
}

fn write_old_laser(w: &mut impl Write, name: &str, s: &ScanRecord) -> io::Result<()> {
    write!(w, "{name}")?;
    write_values(w, &s.ranges)?;
    let (l, r) = (&s.laser_pose, &s.robot_pose);
    let t = s.timestamp;
    writeln!(
        w,
        " {} {} {} {} {} {} {t} {HOST} {t}",
        l.x, l.y, l.theta, r.x, r.y, r.theta
    )
}

#[cfg(test)]
mod tests;
