//! One line's fields, read in order by name: every lookup is a `get`, every failure an error
//! naming the file, line, message type and field.

use super::{CarmenError, LineError, Pose2};

/// A finite number in any notation Rust's float parser takes.
pub(super) fn parse_f64(t: &str) -> Option<f64> {
    t.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// An integer, also written as an integral float (`180.0`), within `lo..=hi`.
fn parse_int(t: &str, lo: f64, hi: f64) -> Option<i64> {
    if let Ok(v) = t.parse::<i64>() {
        return (v as f64 >= lo && v as f64 <= hi).then_some(v);
    }
    let v = parse_f64(t)?;
    (v.fract() == 0.0 && v >= lo && v <= hi).then_some(v as i64)
}

/// The fields of one line after its message type, consumed in order.
pub(super) struct Fields<'a> {
    pub(super) file: &'a str,
    pub(super) line: usize,
    pub(super) message: &'static str,
    pub(super) format: &'static str,
    pub(super) toks: Vec<&'a str>,
    pub(super) pos: usize,
}

impl<'a> Fields<'a> {
    fn error(&self, kind: LineError) -> CarmenError {
        CarmenError::Line {
            file: self.file.to_string(),
            line: self.line,
            message: self.message,
            kind: Box::new(kind),
        }
    }

    pub(super) fn remaining(&self) -> usize {
        self.toks.len().saturating_sub(self.pos)
    }

    pub(super) fn next(&mut self, field: &str) -> Result<&'a str, CarmenError> {
        let t = self.toks.get(self.pos).copied();
        let Some(t) = t else {
            return Err(self.error(LineError::MissingField {
                field: field.to_string(),
                format: self.format,
            }));
        };
        self.pos += 1;
        Ok(t)
    }

    pub(super) fn bad(&self, field: &str, expected: &str, found: &str) -> CarmenError {
        self.error(LineError::BadField {
            field: field.to_string(),
            expected: expected.to_string(),
            found: found.to_string(),
        })
    }

    /// A `bad` error about the field just read.
    pub(super) fn bad_prev(&self, field: &str, expected: &str) -> CarmenError {
        let found = self.pos.checked_sub(1).and_then(|i| self.toks.get(i));
        self.bad(field, expected, found.copied().unwrap_or(""))
    }

    pub(super) fn count_mismatch(
        &self,
        what: &'static str,
        expected: usize,
        found: usize,
        hint: String,
    ) -> CarmenError {
        self.error(LineError::CountMismatch {
            what,
            expected,
            found,
            hint,
        })
    }

    pub(super) fn num(&mut self, field: &str) -> Result<f64, CarmenError> {
        let t = self.next(field)?;
        parse_f64(t).ok_or_else(|| self.bad(field, "a finite number", t))
    }

    /// A pose; the heading is wrapped to (-π, π].
    pub(super) fn pose(&mut self, names: [&str; 3]) -> Result<Pose2, CarmenError> {
        let x = self.num(names[0])?;
        let y = self.num(names[1])?;
        let theta = self.num(names[2])?;
        Ok(Pose2::new(x, y, theta))
    }

    pub(super) fn count(&mut self, field: &str) -> Result<usize, CarmenError> {
        let t = self.next(field)?;
        let v = parse_int(t, 0.0, 1e9).and_then(|v| usize::try_from(v).ok());
        v.ok_or_else(|| self.bad(field, "a non-negative integer", t))
    }

    pub(super) fn int(&mut self, field: &str) -> Result<i32, CarmenError> {
        let t = self.next(field)?;
        let v = parse_int(t, i32::MIN as f64, i32::MAX as f64).and_then(|v| i32::try_from(v).ok());
        v.ok_or_else(|| self.bad(field, "an integer", t))
    }

    /// `n` ranges; `inf` is allowed (no return), NaN and negative values are not.
    pub(super) fn ranges(&mut self, n: usize) -> Result<Vec<f32>, CarmenError> {
        let mut out = Vec::with_capacity(n.min(self.remaining()));
        for i in 0..n {
            let field = || format!("range_readings[{i}]");
            let t = self.next(&field())?;
            match t.parse::<f32>() {
                Ok(r) if r >= 0.0 => out.push(r),
                _ => return Err(self.bad(&field(), "a range in metres (≥ 0 or inf)", t)),
            }
        }
        Ok(out)
    }

    /// `n` finite remission values.
    pub(super) fn remissions(&mut self, n: usize) -> Result<Vec<f32>, CarmenError> {
        let mut out = Vec::with_capacity(n.min(self.remaining()));
        for i in 0..n {
            let field = || format!("remission_values[{i}]");
            let t = self.next(&field())?;
            match t.parse::<f32>() {
                Ok(v) if v.is_finite() => out.push(v),
                _ => return Err(self.bad(&field(), "a finite number", t)),
            }
        }
        Ok(out)
    }

    /// `timestamp hostname logger_timestamp`; returns the timestamp.
    pub(super) fn trailer(&mut self) -> Result<f64, CarmenError> {
        let timestamp = self.num("timestamp")?;
        self.next("hostname")?;
        self.num("logger_timestamp")?;
        Ok(timestamp)
    }

    pub(super) fn end(&self) -> Result<(), CarmenError> {
        let Some(first) = self.toks.get(self.pos) else {
            return Ok(());
        };
        Err(self.error(LineError::ExtraFields {
            count: self.remaining(),
            first: first.to_string(),
            format: self.format,
        }))
    }
}
