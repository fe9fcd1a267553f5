//! SCANS files: laser scans with the true sensor pose of each, for scan-matching experiments
//! (`sim scans` writes them, `sim match` and `sim experiment de-match` read them). The layout
//! follows the CSV files of the thesis's ScanMatchingDatabase ([Hospital thesis §7.2]:
//! one scan per row, true poses for evaluation) with the fields of `sensor_msgs/LaserScan`.
//!
//! Format (CSV, comma-separated, UTF-8, `\n` line ends; fields may be quoted as RFC 4180):
//!
//! ```text
//! index,robot,stamp_s,x,y,theta,angle_min,angle_increment,range_min,range_max,ranges
//! 0,r1,0,3.95,16,0,-2.3561945,0.0043633235,0.5,20,4.012,4.013,inf,...
//! ```
//!
//! * line 1 is exactly that header; every further line is one scan;
//! * `index` — a unique non-negative integer (`sim match --reference I` selects by it);
//! * `robot` — the robot's name; `stamp_s` — simulation time of the scan (s);
//! * `x, y, theta` — the TRUE sensor pose in the world frame (m, m, rad), for evaluation only:
//!   an estimator must never read it;
//! * `angle_min, angle_increment, range_min, range_max` — as in `sensor_msgs/LaserScan` (rad,
//!   rad, m, m); beam `k` points at `angle_min + k · angle_increment` in the sensor frame;
//! * `ranges` — the remaining fields, one per beam (at least one), in metres; REP 117: `inf` =
//!   no return, `-inf` = closer than `range_min`, `nan` = invalid.
//!
//! Reading never panics: every problem is a [`ScansError`] naming the file, the line, the column
//! (1-based field number) or field, and what was expected.

use std::collections::HashMap;
use std::fmt;
use std::io::{Read, Write};
use std::path::Path;
use systems::core::Pose2;
use systems::core::input::{BoundedReader, MAX_DATA_BYTES, MAX_LINE_BYTES};
use systems::matching::scan_to_points;
use systems::sensors::LaserScan;

/// The header line of a SCANS file (without the line end).
pub const SCANS_HEADER: [&str; 11] = [
    "index",
    "robot",
    "stamp_s",
    "x",
    "y",
    "theta",
    "angle_min",
    "angle_increment",
    "range_min",
    "range_max",
    "ranges",
];

/// Fields before the ranges.
const FIXED: usize = SCANS_HEADER.len() - 1;

/// One scan with the true sensor pose.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanRecord {
    pub index: u64,
    pub robot: String,
    /// Simulation time of the scan (s).
    pub stamp: f64,
    /// True sensor pose in the world (evaluation only).
    pub pose: Pose2,
    pub angle_min: f32,
    pub angle_increment: f32,
    pub range_min: f32,
    pub range_max: f32,
    pub ranges: Vec<f32>,
}

impl ScanRecord {
    /// The scan as the sensor published it.
    pub fn laser_scan(&self) -> LaserScan {
        LaserScan {
            stamp: self.stamp,
            angle_min: self.angle_min,
            angle_increment: self.angle_increment,
            range_min: self.range_min,
            range_max: self.range_max,
            ranges: self.ranges.clone(),
        }
    }

    /// Cartesian end points of the valid readings in the sensor frame (eq. 28 of the thesis).
    pub fn points(&self) -> Vec<[f32; 2]> {
        scan_to_points(
            self.angle_min,
            self.angle_increment,
            &self.ranges,
            self.range_min,
            self.range_max,
        )
    }
}

/// What is wrong with a SCANS file: file, line (1-based; 0 = the whole file), column (1-based
/// field number) or field name, and what was expected.
#[derive(Clone, Debug, PartialEq)]
pub struct ScansError {
    pub file: String,
    pub line: u64,
    pub column: Option<usize>,
    pub field: Option<String>,
    pub message: String,
}

impl fmt::Display for ScansError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if self.line > 0 {
            write!(f, ":{}", self.line)?;
            if let Some(c) = self.column {
                write!(f, ":{c}")?;
            }
        }
        write!(f, ": ")?;
        if let Some(name) = &self.field {
            write!(f, "field `{name}`: ")?;
        }
        f.write_str(&self.message)
    }
}

impl std::error::Error for ScansError {}

/// Writes scans as a SCANS file.
pub fn write_scans(path: &Path, scans: &[ScanRecord]) -> anyhow::Result<()> {
    let file = std::fs::File::create(path)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the scans file: {e}", path.display()))?;
    write_scans_to(std::io::BufWriter::new(file), scans)
        .map_err(|e| anyhow::anyhow!("{}: cannot write the scans file: {e}", path.display()))
}

/// Writes scans in the SCANS format to any writer.
pub fn write_scans_to<W: Write>(out: W, scans: &[ScanRecord]) -> anyhow::Result<()> {
    let mut w = csv::WriterBuilder::new()
        .flexible(true)
        .terminator(csv::Terminator::Any(b'\n'))
        .from_writer(out);
    w.write_record(SCANS_HEADER)?;
    let mut row: Vec<String> = Vec::new();
    for s in scans {
        row.clear();
        row.push(s.index.to_string());
        row.push(s.robot.clone());
        // Display of floats is the shortest text that parses back to the same value
        row.push(s.stamp.to_string());
        row.push(s.pose.x.to_string());
        row.push(s.pose.y.to_string());
        row.push(s.pose.theta.to_string());
        row.push(s.angle_min.to_string());
        row.push(s.angle_increment.to_string());
        row.push(s.range_min.to_string());
        row.push(s.range_max.to_string());
        row.extend(s.ranges.iter().map(|r| {
            if r.is_nan() {
                "nan".to_string()
            } else {
                r.to_string()
            }
        }));
        w.write_record(&row)?;
    }
    w.flush()?;
    Ok(())
}

/// Reads a SCANS file.
pub fn read_scans(path: &Path) -> Result<Vec<ScanRecord>, ScansError> {
    let name = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|e| ScansError {
        file: name.clone(),
        line: 0,
        column: None,
        field: None,
        message: format!("cannot read the scans file: {e}"),
    })?;
    // rows are streamed, so the bound is on the file and on each line
    let bounded = BoundedReader::new(file, MAX_DATA_BYTES, MAX_LINE_BYTES);
    parse_scans(std::io::BufReader::new(bounded), &name)
}

/// Parses SCANS text from any reader; `name` is the file name used in errors.
pub fn parse_scans<R: Read>(input: R, name: &str) -> Result<Vec<ScanRecord>, ScansError> {
    let err =
        |line: u64, column: Option<usize>, field: Option<String>, message: String| ScansError {
            file: name.to_string(),
            line,
            column,
            field,
            message,
        };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(input);
    let csv_error = |e: csv::Error| {
        let line = e.position().map_or(0, |p| p.line());
        let message = match e.kind() {
            csv::ErrorKind::Io(io) => format!("cannot read the scans file: {io}"),
            csv::ErrorKind::Utf8 { err, .. } => {
                format!("expected UTF-8 text, found invalid bytes ({err})")
            }
            _ => format!("expected CSV text: {e}"),
        };
        let column = match e.kind() {
            csv::ErrorKind::Utf8 { err, .. } => Some(err.field() + 1),
            _ => None,
        };
        err(line, column, None, message)
    };
    let mut records = reader.records();

    // header
    let header = match records.next() {
        None => {
            return Err(err(
                1,
                None,
                None,
                format!(
                    "expected the header line `{}`, found an empty file",
                    SCANS_HEADER.join(",")
                ),
            ));
        }
        Some(r) => r.map_err(csv_error)?,
    };
    check_header(&header, &err)?;

    let mut scans = Vec::new();
    let mut seen: HashMap<u64, u64> = HashMap::new();
    for rec in records {
        let rec = rec.map_err(csv_error)?;
        let line = rec.position().map_or(0, |p| p.line());
        // a blank line (csv skips truly empty ones; a line of spaces is one empty field)
        if rec.len() == 1 && rec.get(0).is_some_and(|f| f.trim().is_empty()) {
            continue;
        }
        if rec.len() <= FIXED {
            return Err(err(
                line,
                None,
                None,
                format!(
                    "expected at least {} fields ({} fixed fields and one range per beam), found {}",
                    FIXED + 1,
                    FIXED,
                    rec.len()
                ),
            ));
        }
        let (index, scan) = parse_row(&rec, line, &err)?;
        if let Some(first) = seen.insert(index, line) {
            return Err(err(
                line,
                Some(1),
                Some("index".into()),
                format!(
                    "expected a unique scan index, found {index} again (first on line {first})"
                ),
            ));
        }
        scans.push(scan);
    }
    if scans.is_empty() {
        return Err(err(
            0,
            None,
            None,
            "expected at least one scan after the header line, found none".into(),
        ));
    }
    Ok(scans)
}

/// The error of a line: (line, column, field, message).
type LineError<'a> = dyn Fn(u64, Option<usize>, Option<String>, String) -> ScansError + 'a;

/// Checks the header line against [`SCANS_HEADER`].
fn check_header(header: &csv::StringRecord, err: &LineError) -> Result<(), ScansError> {
    for (i, want) in SCANS_HEADER.iter().enumerate() {
        match header.get(i) {
            Some(got) if got.trim() == *want => {}
            Some(got) => {
                return Err(err(
                    1,
                    Some(i + 1),
                    None,
                    format!(
                        "expected the header column `{want}` (header: `{}`), found `{got}`",
                        SCANS_HEADER.join(",")
                    ),
                ));
            }
            None => {
                return Err(err(
                    1,
                    Some(i + 1),
                    None,
                    format!(
                        "expected the header column `{want}` (header: `{}`), found the end of the line",
                        SCANS_HEADER.join(",")
                    ),
                ));
            }
        }
    }
    if header.len() > SCANS_HEADER.len() {
        return Err(err(
            1,
            Some(SCANS_HEADER.len() + 1),
            None,
            format!(
                "expected the header to end after `ranges` (header: `{}`), found `{}`",
                SCANS_HEADER.join(","),
                header.get(SCANS_HEADER.len()).unwrap_or("")
            ),
        ));
    }
    Ok(())
}

/// One scan line (at least [`FIXED`] + 1 fields): its index and the scan.
fn parse_row(
    rec: &csv::StringRecord,
    line: u64,
    err: &LineError,
) -> Result<(u64, ScanRecord), ScansError> {
    let field = |i: usize| rec.get(i).unwrap_or("").trim();
    let bad = |i: usize, what: &str| {
        err(
            line,
            Some(i + 1),
            Some(SCANS_HEADER[i.min(FIXED)].to_string()),
            format!("expected {what}, found `{}`", field(i)),
        )
    };
    let index: u64 = field(0)
        .parse()
        .map_err(|_| bad(0, "a non-negative integer"))?;
    let robot = field(1).to_string();
    if robot.is_empty() {
        return Err(bad(1, "a robot name"));
    }
    let finite64 = |i: usize| -> Result<f64, ScansError> {
        field(i)
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(i, "a finite number"))
    };
    let finite32 = |i: usize| -> Result<f32, ScansError> {
        field(i)
            .parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(i, "a finite number"))
    };
    let stamp = finite64(2)?;
    let (x, y, theta) = (finite64(3)?, finite64(4)?, finite64(5)?);
    let angle_min = finite32(6)?;
    let angle_increment = finite32(7)?;
    if angle_increment == 0.0 {
        return Err(bad(7, "a non-zero angle between beams (rad)"));
    }
    let range_min = finite32(8)?;
    if range_min < 0.0 {
        return Err(bad(8, "a minimum range >= 0 m"));
    }
    let range_max = finite32(9)?;
    if range_max <= range_min {
        return Err(bad(
            9,
            &format!("a maximum range greater than range_min = {range_min} m"),
        ));
    }
    let mut ranges = Vec::with_capacity(rec.len() - FIXED);
    for i in FIXED..rec.len() {
        let text = field(i);
        let r: f32 = text.parse().map_err(|_| {
            err(
                line,
                Some(i + 1),
                Some(format!("ranges[{}]", i - FIXED)),
                format!(
                    "expected a range in metres (a number, `inf`, `-inf` or `nan`), found `{text}`"
                ),
            )
        })?;
        if r.is_finite() && r < 0.0 {
            return Err(err(
                line,
                Some(i + 1),
                Some(format!("ranges[{}]", i - FIXED)),
                format!("expected a range >= 0 m (or `inf`, `-inf`, `nan`), found `{text}`"),
            ));
        }
        ranges.push(r);
    }
    Ok((
        index,
        ScanRecord {
            index,
            robot,
            stamp,
            pose: Pose2::new(x, y, theta),
            angle_min,
            angle_increment,
            range_min,
            range_max,
            ranges,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Vec<ScanRecord> {
        vec![
            ScanRecord {
                index: 0,
                robot: "r1".into(),
                stamp: 0.1,
                pose: Pose2::new(1.5, -2.25, 0.3),
                angle_min: -2.3561945,
                angle_increment: 0.004363323,
                range_min: 0.5,
                range_max: 20.0,
                ranges: vec![1.25, f32::INFINITY, f32::NEG_INFINITY, 3.0e-1],
            },
            ScanRecord {
                index: 7,
                robot: "robot, with comma".into(),
                stamp: 0.30000000000000004,
                pose: Pose2::new(0.0, 0.0, -3.0),
                angle_min: 0.0,
                angle_increment: 0.1,
                range_min: 0.0,
                range_max: 5.0,
                ranges: vec![4.999],
            },
        ]
    }

    fn text(scans: &[ScanRecord]) -> String {
        let mut buf = Vec::new();
        write_scans_to(&mut buf, scans).unwrap();
        String::from_utf8(buf).unwrap()
    }

    fn parse_err(text: &str) -> String {
        match parse_scans(text.as_bytes(), "s.csv") {
            Ok(_) => panic!("should have been rejected:\n{text}"),
            Err(e) => e.to_string(),
        }
    }

    const HEADER: &str =
        "index,robot,stamp_s,x,y,theta,angle_min,angle_increment,range_min,range_max,ranges\n";

    #[test]
    fn round_trip_is_exact() {
        let s = sample();
        let t = text(&s);
        assert!(t.starts_with(HEADER), "{t}");
        assert!(t.contains(",inf,-inf,"), "{t}");
        let back = parse_scans(t.as_bytes(), "s.csv").unwrap();
        assert_eq!(back, s);
    }

    #[test]
    fn nan_ranges_survive() {
        let mut s = sample();
        s[0].ranges[0] = f32::NAN;
        let back = parse_scans(text(&s).as_bytes(), "s.csv").unwrap();
        assert!(back[0].ranges[0].is_nan());
    }

    #[test]
    fn empty_file_and_bad_header() {
        let e = parse_err("");
        assert!(e.starts_with("s.csv:1: expected the header line"), "{e}");
        let e = parse_err("index,robot,stamp,x\n");
        assert!(
            e.starts_with("s.csv:1:3: expected the header column `stamp_s`"),
            "{e}"
        );
        assert!(e.contains("found `stamp`"), "{e}");
        let e = parse_err("index,robot\n");
        assert!(e.starts_with("s.csv:1:3:"), "{e}");
        assert!(e.contains("end of the line"), "{e}");
        let e = parse_err(&format!("{}extra\n", HEADER.trim_end().to_string() + ","));
        assert!(e.starts_with("s.csv:1:12:"), "{e}");
    }

    #[test]
    fn no_scans_is_an_error() {
        let e = parse_err(HEADER);
        assert!(e.contains("at least one scan"), "{e}");
    }

    #[test]
    fn short_row_names_the_line() {
        let e = parse_err(&format!(
            "{HEADER}0,r1,0,0,0,0,0,0.1,0.5,20,1.0\n1,r1,0,0\n"
        ));
        assert!(e.starts_with("s.csv:3: expected at least 11 fields"), "{e}");
        assert!(e.contains("found 4"), "{e}");
    }

    #[test]
    fn bad_fields_name_line_column_and_field() {
        let row = |f: &str| format!("{HEADER}{f}\n");
        let cases = [
            (
                "x,r1,0,0,0,0,0,0.1,0.5,20,1",
                "s.csv:2:1: field `index`",
                "non-negative integer",
            ),
            (
                "-1,r1,0,0,0,0,0,0.1,0.5,20,1",
                "s.csv:2:1: field `index`",
                "found `-1`",
            ),
            (
                "0,,0,0,0,0,0,0.1,0.5,20,1",
                "s.csv:2:2: field `robot`",
                "robot name",
            ),
            (
                "0,r1,abc,0,0,0,0,0.1,0.5,20,1",
                "s.csv:2:3: field `stamp_s`",
                "finite number",
            ),
            (
                "0,r1,0,inf,0,0,0,0.1,0.5,20,1",
                "s.csv:2:4: field `x`",
                "found `inf`",
            ),
            (
                "0,r1,0,0,0,nan,0,0.1,0.5,20,1",
                "s.csv:2:6: field `theta`",
                "finite",
            ),
            (
                "0,r1,0,0,0,0,0,0,0.5,20,1",
                "s.csv:2:8: field `angle_increment`",
                "non-zero",
            ),
            (
                "0,r1,0,0,0,0,0,0.1,-1,20,1",
                "s.csv:2:9: field `range_min`",
                ">= 0",
            ),
            (
                "0,r1,0,0,0,0,0,0.1,0.5,0.4,1",
                "s.csv:2:10: field `range_max`",
                "greater",
            ),
            (
                "0,r1,0,0,0,0,0,0.1,0.5,20,1,2,x",
                "s.csv:2:13: field `ranges[2]`",
                "found `x`",
            ),
            (
                "0,r1,0,0,0,0,0,0.1,0.5,20,-2",
                "s.csv:2:11: field `ranges[0]`",
                ">= 0",
            ),
        ];
        for (r, start, frag) in cases {
            let e = parse_err(&row(r));
            assert!(e.starts_with(start), "{r}: {e}");
            assert!(e.contains(frag), "{r}: expected `{frag}` in {e}");
        }
    }

    #[test]
    fn duplicate_index_points_at_the_first() {
        let e = parse_err(&format!(
            "{HEADER}3,r1,0,0,0,0,0,0.1,0.5,20,1\n3,r1,0,0,0,0,0,0.1,0.5,20,1\n"
        ));
        assert!(e.starts_with("s.csv:3:1: field `index`"), "{e}");
        assert!(e.contains("first on line 2"), "{e}");
    }

    #[test]
    fn unreadable_file_and_bad_bytes() {
        let e = read_scans(Path::new("/nonexistent/scans.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("/nonexistent/scans.csv: cannot read"), "{e}");
        let mut bytes = HEADER.as_bytes().to_vec();
        bytes.extend_from_slice(b"0,r\xff1,0,0,0,0,0,0.1,0.5,20,1\n");
        let e = parse_scans(&bytes[..], "s.csv").unwrap_err().to_string();
        assert!(e.starts_with("s.csv:2:2: expected UTF-8"), "{e}");
    }

    #[test]
    fn points_follow_the_beam_geometry() {
        let s = &sample()[0];
        let p = s.points();
        // only the 1.25 m reading is valid (inf, -inf dropped, 0.3 < range_min)
        assert_eq!(p.len(), 1);
        let a = s.angle_min as f64;
        assert!((p[0][0] as f64 - 1.25 * a.cos()).abs() < 1e-5);
    }
}
