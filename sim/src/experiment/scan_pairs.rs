//! Scan pairs for the scan-matching experiment and benchmark, after the protocol of
//! [Hospital thesis §7.2]: scans captured in-process from a bundled scenario at a fixed
//! period (a "step" is one scan of one robot), a random reference scan and a test scan a given
//! number of steps later on the same robot's stream.

use crate::formats::scans::ScanRecord;
use crate::run::{ScanCapture, capture_scans};
use crate::scenario::{Scenario, find_scenario, load_scenario};
use rand::RngExt;
use systems::core::{Pose2, SimRng};
use systems::sensors::LaserSpec;

/// Beams of the SICK LMS100 the experiment's time target is stated for.
pub const LMS100_BEAMS: usize = 1081;

/// One robot's scans in time order.
#[derive(Clone, Debug)]
pub struct Stream {
    pub robot: String,
    pub scans: Vec<ScanRecord>,
}

/// The captured scans of one scenario.
#[derive(Clone, Debug)]
pub struct ScenarioScans {
    pub name: String,
    /// The scans as captured (index order), for writing a SCANS file.
    pub all: Vec<ScanRecord>,
    /// Per robot, trailing stationary scans removed.
    pub streams: Vec<Stream>,
    /// Robots whose laser was replaced by a SICK LMS100 (it had another beam count).
    pub replaced_lasers: Vec<String>,
    /// Mean true speed over the kept streams (m/s).
    pub mean_speed: f64,
    pub period_s: f64,
}

/// Loads a bundled scenario by name.
pub fn bundled(name: &str) -> anyhow::Result<Scenario> {
    Ok(load_scenario(&find_scenario(name)?)?)
}

/// Captures one scan per robot every `period_s` of `scenario` (optionally only its first
/// `duration` seconds). A laser without 1081 beams is replaced by a SICK LMS100 (keeping its
/// mount and rate) so that every scan is a 1081-beam scan.
pub fn capture(
    scenario: &Scenario,
    period_s: f64,
    duration: Option<f64>,
    threads: usize,
) -> anyhow::Result<ScenarioScans> {
    let mut sc = scenario.clone();
    if let Some(d) = duration {
        sc.duration = sc.duration.min(d);
    }
    let mut replaced = Vec::new();
    for r in &mut sc.robots {
        if let Some(l) = &mut r.laser
            && l.beams() != LMS100_BEAMS
        {
            *l = LaserSpec {
                mount: l.mount,
                rate: l.rate,
                ..LaserSpec::sick_lms100()
            };
            replaced.push(r.name.clone());
        }
    }
    let all = capture_scans(
        &sc,
        &ScanCapture {
            period_s,
            robots: None,
        },
        threads,
        false,
    )?;
    let mut streams: Vec<Stream> = Vec::new();
    for r in &sc.robots {
        let mut scans: Vec<ScanRecord> =
            all.iter().filter(|s| s.robot == r.name).cloned().collect();
        if scans.is_empty() {
            continue;
        }
        // a robot that has arrived stands still: its last scans are the same view again and
        // again, which is not the driving the protocol asks for
        let last = scans[scans.len() - 1].pose;
        let moved = |p: &Pose2| {
            p.distance(&last) > 1e-3 || systems::core::wrap_angle(p.theta - last.theta).abs() > 1e-3
        };
        let keep = scans
            .iter()
            .rposition(|s| moved(&s.pose))
            .map_or(1, |k| k + 2);
        scans.truncate(keep.min(scans.len()));
        streams.push(Stream {
            robot: r.name.clone(),
            scans,
        });
    }
    let (mut dist, mut time) = (0.0, 0.0);
    for s in &streams {
        for w in s.scans.windows(2) {
            dist += w[0].pose.distance(&w[1].pose);
            time += w[1].stamp - w[0].stamp;
        }
    }
    Ok(ScenarioScans {
        name: sc.name.clone(),
        all,
        streams,
        replaced_lasers: replaced,
        mean_speed: if time > 0.0 { dist / time } else { 0.0 },
        period_s,
    })
}

/// A (reference, current) pair: scenario slot, stream, scan positions in the stream.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pair {
    pub scenario: usize,
    pub stream: usize,
    pub reference: usize,
    pub current: usize,
    /// Steps between them.
    pub steps: usize,
    /// The true transform `P_ref⁻¹ ⊕ P_cur` (sensor poses).
    pub truth: Pose2,
}

impl Pair {
    pub fn reference<'a>(&self, data: &'a [ScenarioScans]) -> &'a ScanRecord {
        &data[self.scenario].streams[self.stream].scans[self.reference]
    }

    pub fn current<'a>(&self, data: &'a [ScenarioScans]) -> &'a ScanRecord {
        &data[self.scenario].streams[self.stream].scans[self.current]
    }
}

/// Whether the scan at position `i` of a stream has a partner `steps` later: in the stream,
/// exactly `steps` periods later in time (no gap from a laser fault), and with a true transform
/// inside the search window `max_xy`.
fn partner(s: &Stream, i: usize, steps: usize, period: f64, max_xy: f64) -> Option<Pose2> {
    let j = i + steps;
    let (a, b) = (s.scans.get(i)?, s.scans.get(j)?);
    if ((b.stamp - a.stamp) - steps as f64 * period).abs() > 0.5 * period {
        return None;
    }
    let t = a.pose.between(&b.pose);
    (t.x.abs() <= max_xy && t.y.abs() <= max_xy).then_some(t)
}

/// Draws a reference position uniformly over all scans of a scenario that have a partner for
/// every step count in `steps`; `None` if there is none.
fn draw_reference(
    data: &ScenarioScans,
    steps: &[usize],
    max_xy: f64,
    rng: &mut SimRng,
) -> Option<(usize, usize)> {
    let total: usize = data.streams.iter().map(|s| s.scans.len()).sum();
    if total == 0 {
        return None;
    }
    for _ in 0..100_000 {
        let mut k = rng.random_range(0..total);
        let mut si = 0;
        while k >= data.streams[si].scans.len() {
            k -= data.streams[si].scans.len();
            si += 1;
        }
        let s = &data.streams[si];
        if steps
            .iter()
            .all(|&n| partner(s, k, n, data.period_s, max_xy).is_some())
        {
            return Some((si, k));
        }
    }
    None
}

/// `n` pairs, alternating between the scenarios, the step counts cycling through `steps`
/// (pair `j`: scenario `j mod S`, steps `steps[(j / S) mod len]`), each with its own random
/// reference.
pub fn draw_pairs(
    data: &[ScenarioScans],
    n: usize,
    steps: &[usize],
    max_xy: f64,
    rng: &mut SimRng,
) -> anyhow::Result<Vec<Pair>> {
    let mut out = Vec::with_capacity(n);
    for j in 0..n {
        let sc = j % data.len();
        let k = steps[(j / data.len()) % steps.len()];
        let (stream, i) = draw_reference(&data[sc], &[k], max_xy, rng).ok_or_else(|| {
            anyhow::anyhow!("{}: no scan has a partner {k} steps later", data[sc].name)
        })?;
        let truth = partner(&data[sc].streams[stream], i, k, data[sc].period_s, max_xy)
            .unwrap_or(Pose2::IDENTITY);
        out.push(Pair {
            scenario: sc,
            stream,
            reference: i,
            current: i + k,
            steps: k,
            truth,
        });
    }
    Ok(out)
}

/// The thesis's final protocol: `references` random reference scans (alternating between the
/// scenarios), each paired with the scans every step count of `steps` later.
pub fn draw_reference_sets(
    data: &[ScenarioScans],
    references: usize,
    steps: &[usize],
    max_xy: f64,
    rng: &mut SimRng,
) -> anyhow::Result<Vec<Pair>> {
    let mut out = Vec::with_capacity(references * steps.len());
    for r in 0..references {
        let sc = r % data.len();
        let (stream, i) = draw_reference(&data[sc], steps, max_xy, rng).ok_or_else(|| {
            anyhow::anyhow!(
                "{}: no scan has partners {steps:?} steps later",
                data[sc].name
            )
        })?;
        for &k in steps {
            let truth = partner(&data[sc].streams[stream], i, k, data[sc].period_s, max_xy)
                .unwrap_or(Pose2::IDENTITY);
            out.push(Pair {
                scenario: sc,
                stream,
                reference: i,
                current: i + k,
                steps: k,
                truth,
            });
        }
    }
    Ok(out)
}
