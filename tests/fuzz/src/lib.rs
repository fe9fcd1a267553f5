//! What each fuzz target feeds its input to: one function per reader of user files. Every
//! function must return (the input loads or is refused with an error) for any bytes: a panic,
//! an abort, an input that runs past libFuzzer's `-timeout` or an allocation past its
//! `-malloc_limit_mb` is a failure (`tests/fuzz/run.sh` sets both).
//!
//! Readers that take a path get the input written to a file in this process's own temporary
//! folder, which also holds a small map, places file and road file that scenarios may name.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The stack of the thread each input of a parsing target runs on: a 16th of a main thread's
/// 8 MiB. Recursion that deepens with the input (nested keys, values, elements) then overflows
/// at the input sizes libFuzzer makes, instead of only past what it ever tries; the readers'
/// own depth limits must hold well within it.
pub const SMALL_STACK: usize = 512 * 1024;

/// The alternate stack libFuzzer's crash handler runs on when an input thread's stack
/// overflowed (it prints a stack trace, then writes the input to its artifacts).
const SIGNAL_STACK: usize = 256 * 1024;

/// Runs `f` on a thread of [`SMALL_STACK`] bytes of stack; its panic is the caller's. An
/// overflow is a crash that libFuzzer reports with its input, as any other.
pub fn on_small_stack(f: impl FnOnce() + Send) {
    static HANDLER_ON_ITS_OWN_STACK: std::sync::Once = std::sync::Once::new();
    // libFuzzer installs its SIGSEGV handler without SA_ONSTACK (no Rust runtime set one up
    // before it, whose flag it would keep): on an overflowed stack the handler could not run
    // and the process died with no artifact
    HANDLER_ON_ITS_OWN_STACK.call_once(|| {
        // SAFETY: reads the current action and sets it again with one more flag
        unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            if libc::sigaction(libc::SIGSEGV, std::ptr::null(), &mut action) == 0 {
                action.sa_flags |= libc::SA_ONSTACK;
                libc::sigaction(libc::SIGSEGV, &action, std::ptr::null_mut());
            }
        }
    });
    std::thread::scope(|s| {
        let worker = std::thread::Builder::new()
            .stack_size(SMALL_STACK)
            .spawn_scoped(s, || {
                let _signal_stack = SignalStack::install();
                f();
            })
            .expect("a thread for the input");
        if let Err(panic) = worker.join() {
            std::panic::resume_unwind(panic);
        }
    });
}

/// An alternate signal stack for the calling thread, switched off before it is freed.
struct SignalStack {
    /// The stack's memory: only the kernel uses it, while it is installed.
    _memory: Vec<u8>,
}

impl SignalStack {
    fn install() -> SignalStack {
        let mut stack = vec![0u8; SIGNAL_STACK];
        let on = libc::stack_t {
            ss_sp: stack.as_mut_ptr().cast(),
            ss_flags: 0,
            ss_size: stack.len(),
        };
        // SAFETY: the buffer lives until `drop`, which switches the alternate stack off first
        unsafe { libc::sigaltstack(&on, std::ptr::null_mut()) };
        SignalStack { _memory: stack }
    }
}

impl Drop for SignalStack {
    fn drop(&mut self) {
        let off = libc::stack_t {
            ss_sp: std::ptr::null_mut(),
            ss_flags: libc::SS_DISABLE,
            ss_size: 0,
        };
        // SAFETY: switches this thread's alternate stack off; the buffer is freed after
        unsafe { libc::sigaltstack(&off, std::ptr::null_mut()) };
    }
}

/// This process's scratch folder, with the files scenarios may refer to.
fn scratch() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("sim-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a scratch folder");
        // the repository's assets, as `assets/...` (the seed scenarios name their maps so)
        let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
        let _ = std::os::unix::fs::symlink(assets, dir.join("assets"));
        // a 20 × 10 cell map, walled, 0.1 m per cell
        let mut pgm = b"P5\n20 10\n255\n".to_vec();
        for y in 0..10 {
            for x in 0..20 {
                let wall = x == 0 || y == 0 || x == 19 || y == 9;
                pgm.push(if wall { 0 } else { 254 });
            }
        }
        std::fs::write(dir.join("room.pgm"), pgm).expect("room.pgm");
        std::fs::write(
            dir.join("room.yaml"),
            "image: room.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n\
             occupied_thresh: 0.65\nfree_thresh: 0.196\n",
        )
        .expect("room.yaml");
        std::fs::write(
            dir.join("places.toml"),
            "[places.dock]\npose = [0.5, 0.5, 0.0]\n",
        )
        .expect("places.toml");
        dir
    })
}

/// Writes `data` to `name` in the scratch folder; its path.
fn file(name: &str, data: &[u8]) -> PathBuf {
    let p = scratch().join(name);
    std::fs::write(&p, data).expect("the scratch folder is writable");
    p
}

/// Splits `data` at the first line `sep` into two parts (the second empty without one).
fn two_parts<'a>(data: &'a [u8], sep: &str) -> (&'a [u8], &'a [u8]) {
    let sep = format!("\n{sep}\n");
    let sep = sep.as_bytes();
    match data.windows(sep.len()).position(|w| w == sep) {
        Some(i) => (&data[..i], &data[i + sep.len()..]),
        None => (data, &[]),
    }
}

/// A scenario file's text (paths relative to the scratch folder, where `room.yaml`,
/// `places.toml` and the repository's `assets/` may be named).
pub fn scenario(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(scenario) = sim::scenario::parse_scenario(text, "fuzz.toml", scratch(), "fuzz") else {
        return;
    };
    // a small world also runs its first ticks (behaviours, navigators, events, physics); the
    // bundled floors take 0.1–1 s to build, which would leave no time for mutations
    let cells = scenario.grid.width * scenario.grid.height;
    let localizers: usize = scenario.robots.iter().map(|r| r.localizers.len()).sum();
    if cells <= 250_000 && localizers <= 4 && scenario.robots.len() + scenario.people.len() <= 8 {
        let built = sim::Simulation::from_scenario(scenario)
            .kernel_pool(systems::core::KernelPool::inline())
            .build();
        if let Ok(mut world) = built {
            for _ in 0..10 {
                if world.is_over() || world.step().is_err() {
                    break;
                }
            }
        }
    }
}

/// Values at the edges of what a scenario's numbers may be: huge, tiny, zero, negative, not
/// finite, past 32 bits.
const EDGE_NUMBERS: [&str; 12] = [
    "1e9",
    "-1e9",
    "1e-9",
    "0",
    "0.0",
    "-1",
    "1e300",
    "-1e300",
    "nan",
    "inf",
    "-inf",
    "4294967296",
];

/// The scenario target's mutation: half the time, when the input is a TOML document, one of
/// its values anywhere (in tables, arrays and inline tables) is replaced: a number by one at
/// the edges ([`EDGE_NUMBERS`]) or scaled by a power of ten, a bool flipped, a string
/// emptied. The result is still a document, so the scenario's validation and the run behind
/// it see the value. Otherwise libFuzzer's own byte mutations run (with the dictionary).
pub fn mutate_scenario(data: &mut [u8], size: usize, max_size: usize, seed: u32) -> usize {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand::rngs::SmallRng::seed_from_u64(u64::from(seed));
    if rng.random_bool(0.5)
        && let Some(text) = mutate_one_value(&data[..size], &mut rng)
        && text.len() <= max_size
    {
        data[..text.len()].copy_from_slice(text.as_bytes());
        return text.len();
    }
    // inputs grow a little at a time, as libFuzzer's own length control would have them (it
    // is off with a custom mutator): long scenarios are slow and add no coverage
    libfuzzer_sys::fuzzer_mutate(data, size, max_size.min(size + MAX_GROWTH))
}

/// The most bytes one byte-level mutation of a scenario adds.
const MAX_GROWTH: usize = 256;

/// `input` with one of its values changed, or None if it is not a TOML document with values.
fn mutate_one_value(input: &[u8], rng: &mut impl rand::RngExt) -> Option<String> {
    use toml_edit::Value;
    let mut doc: toml_edit::DocumentMut = std::str::from_utf8(input).ok()?.parse().ok()?;
    let mut count = 0;
    each_value(doc.as_item_mut(), &mut |_| count += 1);
    if count == 0 {
        return None;
    }
    let chosen = rng.random_range(0..count);
    let edge = EDGE_NUMBERS[rng.random_range(0..EDGE_NUMBERS.len())];
    let power = rng.random_range(-6..=9);
    let scale = rng.random_bool(0.3);
    let mut i = 0;
    each_value(doc.as_item_mut(), &mut |v| {
        if i == chosen {
            let new = match v {
                Value::Float(f) if scale => Some(Value::from(f.value() * 10f64.powi(power))),
                Value::Integer(n) if scale => Some(Value::from(
                    n.value().saturating_mul(10i64.pow(power.max(0) as u32)),
                )),
                Value::Float(_) | Value::Integer(_) => edge.parse::<Value>().ok(),
                Value::Boolean(b) => Some(Value::from(!b.value())),
                Value::String(_) => Some(Value::from("")),
                _ => None,
            };
            if let Some(new) = new {
                *v = new.decorated(" ", "");
            }
        }
        i += 1;
    });
    Some(doc.to_string())
}

/// Calls `f` on every scalar value under `item`, depth first.
fn each_value(item: &mut toml_edit::Item, f: &mut impl FnMut(&mut toml_edit::Value)) {
    match item {
        toml_edit::Item::Value(v) => each_value_in(v, f),
        toml_edit::Item::Table(t) => {
            for (_, item) in t.iter_mut() {
                each_value(item, f);
            }
        }
        toml_edit::Item::ArrayOfTables(a) => {
            for t in a.iter_mut() {
                for (_, item) in t.iter_mut() {
                    each_value(item, f);
                }
            }
        }
        toml_edit::Item::None => {}
    }
}

fn each_value_in(v: &mut toml_edit::Value, f: &mut impl FnMut(&mut toml_edit::Value)) {
    match v {
        toml_edit::Value::Array(a) => {
            for v in a.iter_mut() {
                each_value_in(v, f);
            }
        }
        toml_edit::Value::InlineTable(t) => {
            for (_, v) in t.iter_mut() {
                each_value_in(v, f);
            }
        }
        scalar => f(scalar),
    }
}

/// `--set KEY=VALUE` overrides, one per line, applied to a bundled-style scenario.
pub fn overrides(data: &[u8]) {
    static SOURCE: OnceLock<sim::scenario::source::Source> = OnceLock::new();
    let source = SOURCE.get_or_init(|| {
        sim::scenario::source::Source::from_text(ROOM, "room.toml", scratch(), "room")
            .expect("the base scenario loads")
    });
    let text = String::from_utf8_lossy(data);
    let sets: Vec<String> = text.lines().map(str::to_string).collect();
    if let Ok(plan) = sim::batch::sets::plan_sets(&sets, &[], &[]) {
        for set in &plan.sets {
            let _ = source.scenario(set);
        }
    }
}

/// The scenario the overrides edit: the room map, a robot with every sensor and a localizer.
const ROOM: &str = r#"
name = "room"
duration = 1.0
[map]
file = "room.yaml"
places = "places.toml"
[[robots]]
name = "r1"
start = "dock"
behaviour = { type = "waypoints", points = [[1.5, 0.5]] }
[robots.sensors.laser]
[robots.sensors.encoder]
[[robots.localization]]
type = "mcl"
"#;

/// A map_server YAML, then a line `---`, then its image (PGM, or PNG when it starts so).
pub fn map(data: &[u8]) {
    let (yaml, image) = two_parts(data, "---");
    let name = if image.starts_with(b"\x89PNG") {
        "map.png"
    } else {
        "map.pgm"
    };
    file(name, image);
    let y = file("map.yaml", yaml);
    let _ = systems::world::load_map(&y);
}

/// A places file, named by a scenario on the room map.
pub fn places(data: &[u8]) {
    let p = file("fuzz-places.toml", data);
    let text = format!(
        "duration = 1.0\n[map]\nfile = \"room.yaml\"\nplaces = \"{}\"\n",
        p.display()
    );
    let _ = sim::scenario::parse_scenario(&text, "places.toml", scratch(), "places");
}

/// A road file: OSM XML when it starts with `<?xml` or `<osm`, GPX otherwise.
pub fn roads(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let t = text.trim_start();
    let name = if t.starts_with("<osm") || (t.starts_with("<?xml") && t.contains("<osm")) {
        "fuzz.osm"
    } else {
        "fuzz.gpx"
    };
    let options = systems::world::roads::RoadOptions::default();
    let _ = systems::world::roads::parse_roads(&text, Path::new(name), &options);
}

/// A CARMEN log; one of a few scans also goes through `sim slam` (scan-to-map SLAM, whose map
/// grows to wherever the log's poses are).
pub fn carmen(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let options = sim::formats::carmen::CarmenReadOptions::default();
    let Ok(log) = sim::formats::carmen::parse_carmen(&text, "fuzz.log", &options) else {
        return;
    };
    if log.scans.len() + log.rear_scans.len() <= 20 {
        let path = file("fuzz.log", data);
        let path = path.to_str().expect("a UTF-8 scratch path");
        let args = ["--carmen", path, "--no-rrd", "--quiet", "--threads", "1"];
        if let Ok(a) = sim::options::parse_args::<sim::log_slam::SlamArgs>(&args) {
            let _ = sim::log_slam::run_slam_command(&a);
        }
    }
}

/// A SCANS file (CSV).
pub fn scans(data: &[u8]) {
    let _ = sim::formats::scans::parse_scans(data, "fuzz.scans");
}

/// An MCAP file: read strictly and recovering; every message of a known ROS 2 type decoded.
pub fn mcap(data: &[u8]) {
    use sim::record::mcap::McapRecording;
    let path = Path::new("fuzz.mcap");
    let _ = McapRecording::from_bytes(path, data, false);
    if let Ok(rec) = McapRecording::from_bytes(path, data, true) {
        use sim::record::mcap::RosMessage;
        use sim::record::mcap::messages::*;
        for m in &rec.messages {
            let _ = match rec.channels[m.channel].schema_name.as_str() {
                LaserScan::NAME => rec.decode::<LaserScan>(m).map(drop),
                Odometry::NAME => rec.decode::<Odometry>(m).map(drop),
                PoseStamped::NAME => rec.decode::<PoseStamped>(m).map(drop),
                JointState::NAME => rec.decode::<JointState>(m).map(drop),
                TFMessage::NAME => rec.decode::<TFMessage>(m).map(drop),
                NavSatFix::NAME => rec.decode::<NavSatFix>(m).map(drop),
                Imu::NAME => rec.decode::<Imu>(m).map(drop),
                Image::NAME => rec.decode::<Image>(m).map(drop),
                Range::NAME => rec.decode::<Range>(m).map(drop),
                _ => Ok(()),
            };
        }
    }
}

/// Two shards of a batch for `sim batch-merge`: each a `batch.json`, `---`, a `runs.jsonl`,
/// the shards themselves separated by a line `===`.
pub fn batch(data: &[u8]) {
    let (a, b) = two_parts(data, "===");
    let mut shards = Vec::new();
    for (k, shard) in [a, b].into_iter().enumerate() {
        let (manifest, rows) = two_parts(shard, "---");
        let dir = scratch().join(format!("shard{k}"));
        std::fs::create_dir_all(&dir).expect("a shard folder");
        std::fs::write(dir.join("batch.json"), manifest).expect("batch.json");
        std::fs::write(dir.join("runs.jsonl"), rows).expect("runs.jsonl");
        shards.push(dir);
    }
    let args = sim::batch::merge::MergeArgs {
        out: scratch().join("merged"),
        shards,
        quiet: true,
    };
    let _ = sim::batch::merge::merge_command(&args);
}
