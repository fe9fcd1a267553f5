//! Files written and read back: several channels, attachments, interrupted and cut files,
//! garbage.

use super::messages::*;
use super::samples::{self, SCENARIO, write_all_types};
use super::*;
use std::path::{Path, PathBuf};

const SEC: u64 = samples::SEC;

/// A recorder writing `name` in a fresh temporary folder (kept alive by the returned guard).
fn recorder(name: &str) -> (tempfile::TempDir, PathBuf, McapRecorder) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    let rec = McapRecorder::create(&path, ROS2_PROFILE).unwrap();
    (dir, path, rec)
}

fn written(dir: &Path, seconds: u64) -> (PathBuf, Vec<(&'static str, usize)>) {
    let path = dir.join("run.mcap");
    let mut rec = McapRecorder::create(&path, ROS2_PROFILE).unwrap();
    let counts = write_all_types(&mut rec, seconds);
    rec.attach("scenario.toml", "application/toml", SCENARIO.as_bytes())
        .unwrap();
    let stats = rec.finish().unwrap();
    assert_eq!(
        stats.messages as usize,
        counts.iter().map(|c| c.1).sum::<usize>()
    );
    assert_eq!((stats.channels, stats.attachments), (10, 1));
    (path, counts)
}

#[test]
fn several_channels_read_back_in_time_order() {
    let dir = tempfile::tempdir().unwrap();
    let (path, counts) = written(dir.path(), 6);
    let r = McapRecording::open(&path).unwrap();
    assert_eq!(r.profile, "ros2");
    assert!(r.damage.is_none());
    for (topic, n) in &counts {
        let ch = r.channel(topic).unwrap();
        assert_eq!(ch.message_count as usize, *n, "{topic}");
        assert_eq!(ch.message_encoding, "cdr");
        assert_eq!(ch.schema_encoding, "ros2msg");
    }
    assert_eq!(
        r.channel("/scan").unwrap().schema_name,
        "sensor_msgs/msg/LaserScan"
    );
    assert!(
        r.messages
            .windows(2)
            .all(|w| w[0].log_time <= w[1].log_time)
    );
    let a = r.attachment("scenario.toml").unwrap();
    assert_eq!(
        (a.media_type.as_str(), a.data.as_slice()),
        ("application/toml", SCENARIO.as_bytes())
    );
    // Decoded values are the written ones.
    let scans = r.decode_topic::<LaserScan>("/scan").unwrap();
    assert_eq!(scans.len(), 12);
    assert_eq!(scans[3], (SEC + SEC / 2, samples::laser_scan(1.5, 360)));
    let odom = r.decode_topic::<Odometry>("/odom").unwrap();
    assert_eq!(odom[0].1, samples::odometry(0.5));
    assert_eq!(
        r.decode_topic::<Image>("/camera/image_raw").unwrap()[5].1,
        samples::image(5.0, 320, 240)
    );
    assert_eq!(
        r.decode_topic::<TFMessage>("/tf").unwrap()[2].1,
        samples::tf(2.0)
    );
    assert_eq!(
        r.decode_topic::<NavSatFix>("/gps/fix").unwrap()[1].1,
        samples::nav_sat_fix(1.0)
    );
    assert_eq!(
        r.decode_topic::<Imu>("/imu").unwrap()[1].1,
        samples::imu(1.0)
    );
    assert_eq!(
        r.decode_topic::<Range>("/sonar/0").unwrap()[1].1,
        samples::range(1.0)
    );
    assert_eq!(
        r.decode_topic::<JointState>("/joint_states").unwrap()[2].1,
        samples::joint_state(2.0)
    );
    // The wrong type is a clear error.
    let e = r.decode_topic::<Imu>("/scan").unwrap_err().to_string();
    assert!(
        e.contains("/scan carries `sensor_msgs/msg/LaserScan`"),
        "{e}"
    );
}

#[test]
fn a_topic_keeps_its_type_and_schemas_are_shared() {
    let (_dir, _, mut rec) = recorder("t.mcap");
    let a = rec.channel::<LaserScan>("/scan").unwrap();
    let b = rec.channel::<LaserScan>("/scan").unwrap();
    let c = rec.channel::<LaserScan>("/scan2").unwrap();
    assert_eq!(a.id(), b.id());
    assert_ne!(a.id(), c.id());
    let e = rec.channel::<Imu>("/scan").err().unwrap().to_string();
    assert!(
        e.contains("/scan already carries sensor_msgs/msg/LaserScan"),
        "{e}"
    );
    rec.finish().unwrap();
}

/// Images handed over whole (encoded on the writer thread) give the same file, byte for byte,
/// as images encoded by the caller, with other messages before, between and after them and
/// enough of them to fill several batches and chunks.
#[test]
fn messages_taken_whole_give_the_same_file() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, owned: bool| {
        let path = dir.path().join(name);
        let mut rec = McapRecorder::create(&path, ROS2_PROFILE).unwrap();
        let cam = rec.channel::<Image>("/camera/image_raw").unwrap();
        let scan = rec.channel::<LaserScan>("/scan").unwrap();
        for i in 0..40u64 {
            let t = i as f64 * 0.25;
            for k in 0..60 {
                let stamp = i * SEC / 4 + k;
                rec.write(scan, stamp, &samples::laser_scan(t, 90)).unwrap();
            }
            let image = samples::image(t, 64 + i as u32, 48);
            if owned {
                rec.write_owned(cam, i * SEC / 4, image).unwrap();
            } else {
                rec.write(cam, i * SEC / 4, &image).unwrap();
            }
        }
        let stats = rec.finish().unwrap();
        assert_eq!(stats.messages, 40 * 61);
        assert!(stats.chunks > 1, "{stats:?}");
        std::fs::read(&path).unwrap()
    };
    let encoded = write("encoded.mcap", false);
    let owned = write("owned.mcap", true);
    assert!(encoded == owned, "the files differ");
    let r = McapRecording::open(&dir.path().join("owned.mcap")).unwrap();
    let images = r.decode_topic::<Image>("/camera/image_raw").unwrap();
    assert_eq!(images[7], (7 * SEC / 4, samples::image(1.75, 71, 48)));
}

#[test]
fn the_flush_period_ends_chunks() {
    let (_dir, _, mut rec) = recorder("f.mcap");
    rec.set_flush_period(Some(SEC));
    let ch = rec.channel::<Range>("/r").unwrap();
    for i in 0..50 {
        rec.write(ch, i * SEC / 5, &samples::range(0.0)).unwrap();
    }
    let stats = rec.finish().unwrap();
    assert_eq!(stats.chunks, 10, "one chunk per second of log time");
}

#[test]
fn an_interrupted_writer_leaves_its_flushed_chunks_readable() {
    let (_dir, path, mut rec) = recorder("crash.mcap");
    rec.set_flush_period(None);
    let scan = rec.channel::<LaserScan>("/scan").unwrap();
    let cam = rec.channel::<Image>("/camera").unwrap();
    for i in 0..10 {
        rec.write(scan, i * SEC, &samples::laser_scan(i as f64, 100))
            .unwrap();
    }
    rec.flush().unwrap();
    for i in 10..15 {
        rec.write(cam, i * SEC, &samples::image(i as f64, 320, 240))
            .unwrap();
    }
    rec.abandon(); // the process dies: no summary, unflushed bytes lost
    let e = McapRecording::open(&path).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("{}: truncated MCAP file", path.display())),
        "{e}"
    );
    assert!(e.contains("after 10 messages"), "{e}");
    let r = McapRecording::open_recovering(&path).unwrap();
    assert!(r.damage.as_deref().unwrap().contains("truncated"));
    assert_eq!(r.messages.len(), 10);
    assert_eq!(
        r.decode_topic::<LaserScan>("/scan").unwrap()[9].1,
        samples::laser_scan(9.0, 100)
    );
}

#[test]
fn a_cut_file_is_an_error_or_recovers_a_prefix() {
    let (_dir, path, mut rec) = recorder("small.mcap");
    rec.set_flush_period(Some(SEC));
    let ch = rec.channel::<Odometry>("/odom").unwrap();
    for i in 0..40 {
        rec.write(ch, i * SEC / 4, &samples::odometry(i as f64))
            .unwrap();
    }
    rec.finish().unwrap();
    let full = std::fs::read(&path).unwrap();
    let mut last = 0;
    for cut in (0..full.len())
        .step_by(97)
        .chain([full.len() / 2, full.len() - 1])
    {
        let bytes = &full[..cut];
        let e = McapRecording::from_bytes(&path, bytes, false)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(&path.display().to_string()), "{e}");
        assert!(
            e.contains("truncated") || e.contains("not an MCAP file"),
            "cut {cut}: {e}"
        );
        if let Ok(r) = McapRecording::from_bytes(&path, bytes, true) {
            let got = r.decode_topic::<Odometry>("/odom").unwrap_or_default();
            for (i, (t, m)) in got.iter().enumerate() {
                assert_eq!((*t, m), (i as u64 * SEC / 4, &samples::odometry(i as f64)));
            }
            assert!(
                got.len() >= last || cut == full.len() / 2,
                "prefix shrank at {cut}"
            );
            last = got.len();
        }
    }
    assert_eq!(last, 40, "everything but the end magic is recovered");
}

/// A file as other writers make it (rosbag2's MCAP storage and Foxglove's Python writers
/// compress chunks with zstd; some write none or lz4) reads back whole, whatever the chunks'
/// compression; a compression we do not read is named, not called corruption.
#[test]
fn zstd_lz4_and_uncompressed_chunks_read_back() {
    let write = |compression: Option<mcap::Compression>| {
        let mut out = std::io::Cursor::new(Vec::new());
        let mut w = mcap::WriteOptions::new()
            .profile(ROS2_PROFILE)
            .compression(compression)
            .chunk_size(Some(4096))
            .create(&mut out)
            .unwrap();
        let schema = w
            .add_schema(
                Odometry::NAME,
                schema::SCHEMA_ENCODING,
                Odometry::DEFINITION.as_bytes(),
            )
            .unwrap();
        let ch = w
            .add_channel(schema, "/odom", "cdr", &Default::default())
            .unwrap();
        for i in 0..200u32 {
            let header = mcap::records::MessageHeader {
                channel_id: ch,
                sequence: i,
                log_time: i as u64 * SEC / 10,
                publish_time: i as u64 * SEC / 10,
            };
            let data = cdr::encode(&samples::odometry(i as f64));
            w.write_to_known_channel(&header, &data).unwrap();
        }
        w.finish().unwrap();
        drop(w);
        out.into_inner()
    };
    let path = Path::new("other.mcap");
    for c in [
        None,
        Some(mcap::Compression::Lz4),
        Some(mcap::Compression::Zstd),
    ] {
        let bytes = write(c);
        let r = McapRecording::from_bytes(path, &bytes, false).unwrap();
        let got = r.decode_topic::<Odometry>("/odom").unwrap();
        assert_eq!(got.len(), 200, "{c:?}");
        for (i, (t, m)) in got.iter().enumerate() {
            assert_eq!((*t, m), (i as u64 * SEC / 10, &samples::odometry(i as f64)));
        }
    }
    // the same file with its chunks' compression renamed to one nobody reads
    let mut bytes = write(Some(mcap::Compression::Zstd));
    let at = bytes.windows(4).position(|w| w == b"zstd").unwrap();
    bytes[at..at + 4].copy_from_slice(b"zzzz");
    let e = McapRecording::from_bytes(path, &bytes, false)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`zzzz`") && e.contains("lz4 and zstd") && !e.contains("corrupt"),
        "{e}"
    );
}

/// An Attachment record too short for its own header (found by fuzzing: the `mcap` crate
/// sliced past its end) is an error naming the lengths.
#[test]
fn an_attachment_shorter_than_its_header_is_an_error() {
    let mut bytes = mcap::MAGIC.to_vec();
    let record = |bytes: &mut Vec<u8>, op: u8, body: &[u8]| {
        bytes.push(op);
        bytes.extend_from_slice(&(body.len() as u64).to_le_bytes());
        bytes.extend_from_slice(body);
    };
    let mut header = Vec::new();
    for s in ["ros2", "hand-made"] {
        header.extend_from_slice(&(s.len() as u32).to_le_bytes());
        header.extend_from_slice(s.as_bytes());
    }
    record(&mut bytes, mcap::records::op::HEADER, &header);
    for body in [vec![0u8; 12], vec![0u8; 35], {
        // a name 200 bytes long in a 40-byte body
        let mut b = vec![0u8; 40];
        b[16..20].copy_from_slice(&200u32.to_le_bytes());
        b
    }] {
        let mut file = bytes.clone();
        record(&mut file, mcap::records::op::ATTACHMENT, &body);
        record(&mut file, mcap::records::op::FOOTER, &[0u8; 20]);
        file.extend_from_slice(mcap::MAGIC);
        let e = McapRecording::from_bytes(Path::new("short.mcap"), &file, false)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("short.mcap: corrupt MCAP file: Attachment length"),
            "{e}"
        );
    }
}

#[test]
fn garbage_and_flipped_bytes_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let (path, _) = written(dir.path(), 3);
    let full = std::fs::read(&path).unwrap();
    for junk in [
        &b""[..],
        b"MCAP",
        &[0u8; 4096],
        b"\x89MCAP0\r\n\x01\xff\xff\xff\xff\xff\xff\xff\x7f",
    ] {
        let e = McapRecording::from_bytes(&path, junk, true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("MCAP file"), "{e}");
    }
    let data_end = ::mcap::read::footer(&full).unwrap().summary_start as usize;
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    for round in 0..300 {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut bad = full.clone();
        let at = (state >> 17) as usize % bad.len();
        bad[at] ^= 1 << (round % 8);
        let strict = McapRecording::from_bytes(&path, &bad, false);
        let _ = McapRecording::from_bytes(&path, &bad, true);
        if (8..data_end).contains(&at) {
            // In the data section (or its end record): a CRC or record check catches it.
            assert!(strict.is_err(), "flip at {at} of {data_end} went unnoticed");
        }
    }
    let e = McapRecording::open(&dir.path().join("missing.mcap"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.mcap: cannot read"), "{e}");
}

/// A file that takes `room` bytes, then fails every write with "no space left".
struct FillingDisk {
    data: std::io::Cursor<Vec<u8>>,
    room: usize,
}

impl std::io::Write for FillingDisk {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.data.get_ref().len() + buf.len() > self.room {
            return Err(std::io::Error::from(std::io::ErrorKind::StorageFull));
        }
        self.data.write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl std::io::Seek for FillingDisk {
    fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
        self.data.seek(pos)
    }
}

#[test]
fn a_write_error_is_reported_by_flush_and_by_finish() {
    let disk = FillingDisk {
        data: Default::default(),
        room: 8_000,
    };
    let path = Path::new("full.mcap");
    let mut rec = McapRecorder::create_on(path, Box::new(disk), ROS2_PROFILE).unwrap();
    let scan = rec.channel::<LaserScan>("/scan").unwrap();
    for i in 0..400 {
        // the writer thread fails on the way; writing goes on without an error here
        rec.write(scan, i * SEC, &samples::laser_scan(i as f64, 720))
            .unwrap();
    }
    let e = format!("{:#}", rec.flush().unwrap_err());
    assert!(e.starts_with("full.mcap: cannot "), "{e}");
    assert!(e.contains("I/O error"), "{e}");
    rec.write(scan, 401 * SEC, &samples::laser_scan(401.0, 720))
        .unwrap();
    let e2 = format!("{:#}", rec.finish().unwrap_err());
    assert_eq!(e2, e, "the first error again");
}

#[test]
fn channel_ids_run_from_one_and_run_out_with_a_clear_error() {
    let (_dir, path, mut rec) = recorder("many.mcap");
    let first = rec.channel::<Range>("/sonar/0").unwrap();
    let again = rec.channel::<Range>("/sonar/0").unwrap();
    assert_eq!((first.id(), again.id()), (1, 1));
    for k in 1..u16::MAX {
        let ch = rec.channel::<Range>(&format!("/sonar/{k}")).unwrap();
        assert_eq!(ch.id(), k + 1);
    }
    let Err(e) = rec.channel::<Range>("/one/too/many") else {
        panic!("a channel id beyond u16");
    };
    assert_eq!(
        e.to_string(),
        format!("{}: too many channels", path.display())
    );
    let stats = rec.finish().unwrap();
    assert_eq!(stats.channels, u16::MAX as usize);
}
