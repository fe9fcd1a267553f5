//! Reading a user's file whole with a bound on its size, so that no input makes an allocation
//! larger than a stated bound: a regular file larger than the bound is refused before it is
//! read, and anything else (a FIFO, a process substitution, `/dev/zero`) is read up to the
//! bound and refused beyond it.

use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// The most a text file that configures a run may hold (scenarios, places, map YAML,
/// manifests, `batch.json`, SLAM configurations).
pub const MAX_CONFIG_BYTES: u64 = 64 << 20;

/// The most a data file may hold (MCAP and CARMEN logs, road files, batch rows, reports).
pub const MAX_DATA_BYTES: u64 = 4 << 30;

/// The longest line a line-based data file may have (SCANS rows).
pub const MAX_LINE_BYTES: u64 = 64 << 20;

fn too_large(limit: u64) -> Error {
    Error::new(
        ErrorKind::FileTooLarge,
        format!("larger than {}, the most this file may hold", size(limit)),
    )
}

/// `bytes` as MiB or GiB.
fn size(bytes: u64) -> String {
    if bytes >= 1 << 30 {
        format!("{} GiB", bytes >> 30)
    } else {
        format!("{} MiB", bytes >> 20)
    }
}

/// The bytes of `path`, refused (`ErrorKind::FileTooLarge`) beyond `limit` bytes.
pub fn read_bounded(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    let mut bytes = Vec::new();
    if meta.is_file() {
        if meta.len() > limit {
            return Err(too_large(limit));
        }
        bytes.reserve_exact(meta.len() as usize);
    }
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(limit));
    }
    Ok(bytes)
}

/// The text of `path` (UTF-8), refused beyond `limit` bytes.
pub fn read_text_bounded(path: &Path, limit: u64) -> std::io::Result<String> {
    String::from_utf8(read_bounded(path, limit)?).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        Error::new(
            ErrorKind::InvalidData,
            format!("expected UTF-8 text, found invalid bytes after byte {at}"),
        )
    })
}

/// A reader that fails once more than `total` bytes come, or a line runs longer than `line`
/// bytes (a file with no line ends, a stream of zeros), for parsers that stream their input
/// and would otherwise grow one line's buffer, or their records, for ever.
pub struct BoundedReader<R> {
    inner: R,
    total: u64,
    line_limit: u64,
    read: u64,
    line: u64,
}

impl<R> BoundedReader<R> {
    pub fn new(inner: R, total: u64, line: u64) -> Self {
        BoundedReader {
            inner,
            total,
            line_limit: line,
            read: 0,
            line: 0,
        }
    }
}

impl<R: Read> Read for BoundedReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read += n as u64;
        if self.read > self.total {
            return Err(too_large(self.total));
        }
        let mut longest = 0;
        for &b in &buf[..n] {
            self.line = if b == b'\n' { 0 } else { self.line + 1 };
            longest = longest.max(self.line);
        }
        if longest > self.line_limit {
            return Err(Error::new(
                ErrorKind::InvalidData,
                format!(
                    "a line longer than {}, the longest this file may have",
                    size(self.line_limit)
                ),
            ));
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_over_the_bound_is_refused_and_one_at_it_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f");
        std::fs::write(&p, vec![b'x'; 1000]).unwrap();
        assert_eq!(read_bounded(&p, 1000).unwrap().len(), 1000);
        let e = read_bounded(&p, 999).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::FileTooLarge);
        std::fs::write(&p, b"ok \xff").unwrap();
        let e = read_text_bounded(&p, 100).unwrap_err().to_string();
        assert!(e.contains("UTF-8") && e.contains("after byte 3"), "{e}");
    }

    #[test]
    fn an_endless_stream_stops_at_the_bound() {
        // /dev/zero has no length: it is read up to the bound, then refused
        let e = read_bounded(Path::new("/dev/zero"), 1 << 20).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::FileTooLarge);
        assert!(e.to_string().contains("larger than 1 MiB"), "{e}");
    }

    #[test]
    fn a_stream_longer_or_with_a_longer_line_than_its_bounds_fails_the_read() {
        let mut ok = BoundedReader::new(&b"abc\ndef\n"[..], 8, 3);
        let mut s = String::new();
        ok.read_to_string(&mut s).unwrap();
        assert_eq!(s, "abc\ndef\n");
        let mut long = BoundedReader::new(&b"abc\ndefg\nhi\n"[..], 100, 3);
        let e = long.read_to_string(&mut String::new()).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::InvalidData);
        let mut big = BoundedReader::new(&b"abc\ndef\n"[..], 7, 3);
        let e = big.read_to_string(&mut String::new()).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::FileTooLarge);
        let zeros = std::fs::File::open("/dev/zero").unwrap();
        let e = BoundedReader::new(zeros, 1 << 30, 1 << 20).read_to_end(&mut Vec::new());
        assert!(
            e.unwrap_err()
                .to_string()
                .contains("a line longer than 1 MiB")
        );
    }
}
