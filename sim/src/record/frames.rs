//! Whole camera frames for the recordings: the .rrd's JPEG (with the recognized road drawn in)
//! and the MCAP's raw `sensor_msgs/Image`. A run computes only the pixels its road recognizer
//! reads; a recorded frame needs all of them (~0.3 ms for 320×240 with AVX2) and, for the .rrd,
//! a JPEG encoding (~0.3 ms, `rusty_jpeg`). Both happen on a worker thread of the recording, so
//! the simulation does not wait for them; with both outputs a frame is rendered once.
//!
//! Which frames: a camera's frame is recorded when it is at least `1 / record.camera_rate`
//! after the last one recorded (the first frame always).
//!
//! Determinism: a frame is handed to the recorders in the first tick at least
//! [`COLLECT_AFTER`] of simulated time after it was taken (the tick waits for the worker if it
//! is behind), or when the run ends; so what is written, and in which order, does not depend on
//! the worker's speed. The messages of an MCAP file are therefore not in log-time order (a frame
//! follows a few seconds of other messages); readers order them by their log time.

#[cfg(feature = "rrd")]
use super::rrd::RrdRecorder;
#[cfg(feature = "rrd")]
use super::rrd::events::record_events;
use bevy_ecs::prelude::*;
use std::cell::Cell;
use std::collections::VecDeque;
use std::sync::{Arc, Mutex, mpsc};
use std::thread::JoinHandle;
use systems::core::{RobotId, RobotIndex, SimClock, SimPlugin, SimSet};
use systems::navigation::road_recognition::{RoadDetection, RoadDetector, draw_detection};
use systems::sensors::camera::{CameraFrame, CameraImage, FrameView, GroundRays, Palette};
use systems::sensors::{Camera, CameraImages};
use systems::world::roads::{RoadSurface, SurfaceRaster};

/// Simulated time (s) the worker has to finish a frame before the run waits for it. A fast
/// outdoor run simulates a second in about 2 ms, less than a busy worker may take for a frame
/// (0.6 ms of work, sharing the cores with the simulation's own threads and the writers); five
/// seconds keep the run from waiting, for five frames per camera in memory.
pub const COLLECT_AFTER: f64 = 5.0;

/// What a run reports when the frame worker ended early.
const WORKER_STOPPED: &str = "the camera frame worker stopped before rendering every frame";

/// JPEG quality of the .rrd's frames.
const JPEG_QUALITY: u8 = 80;

/// What the recorders want of each frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameOutputs {
    /// The frame as taken (MCAP).
    pub raw: bool,
    /// A JPEG with the road detection drawn in (.rrd).
    pub jpeg: bool,
}

/// One recorded frame.
#[derive(Debug)]
pub struct RecordedFrame {
    pub robot: RobotIndex,
    /// The robot's name.
    pub name: String,
    pub stamp: f64,
    /// The image as the camera took it, if [`FrameOutputs::raw`].
    pub raw: Option<CameraImage>,
    /// The JPEG (or why it failed), if [`FrameOutputs::jpeg`].
    pub jpeg: Option<Result<Vec<u8>, String>>,
}

/// A frame to render.
struct Job {
    robot: RobotIndex,
    name: String,
    frame: CameraFrame,
    rays: Arc<GroundRays>,
    palette: Palette,
    raster: Arc<SurfaceRaster>,
    detection: Option<RoadDetection>,
}

/// The frames being recorded (a resource while a run with a recording lasts).
#[derive(Resource)]
pub struct RecordedFrames {
    period: f64,
    outputs: FrameOutputs,
    /// Per robot (by index): the stamp of the last frame sent to the worker.
    last: Vec<Option<f64>>,
    jobs: Option<mpsc::Sender<Job>>,
    /// In a mutex only because a resource must be `Sync`; reached through `&mut`.
    done: Mutex<mpsc::Receiver<RecordedFrame>>,
    worker: Option<JoinHandle<()>>,
    /// Stamps of the frames sent and not yet collected, oldest first.
    in_flight: VecDeque<f64>,
    /// Grass everywhere, for scenarios without roads.
    grass: Arc<SurfaceRaster>,
    /// The frames collected in this tick, oldest first, for the recorders.
    pub ready: Vec<RecordedFrame>,
    /// The worker stopped early (it panicked); reported when the run ends.
    pub error: Option<String>,
}

impl RecordedFrames {
    /// Starts the worker thread. `camera_rate`: recorded frames per second and camera.
    pub fn new(camera_rate: f64, outputs: FrameOutputs) -> anyhow::Result<Self> {
        let (jobs, queue) = mpsc::channel::<Job>();
        let (finished, done) = mpsc::channel();
        let worker = super::priority::spawn("camera frames", move || {
            for job in queue {
                if finished.send(render(job, outputs)).is_err() {
                    break;
                }
            }
        })?;
        Ok(RecordedFrames {
            period: 1.0 / camera_rate,
            outputs,
            last: Vec::new(),
            jobs: Some(jobs),
            done: Mutex::new(done),
            worker: Some(worker),
            in_flight: VecDeque::new(),
            grass: Arc::new(SurfaceRaster::empty()),
            ready: Vec::new(),
            error: None,
        })
    }

    /// Collects the frames taken at or before `until` (all with `None`), waiting for the worker
    /// as needed, into [`RecordedFrames::ready`].
    fn collect(&mut self, until: Option<f64>) {
        let done = self.done.get_mut().unwrap_or_else(|e| e.into_inner());
        while let Some(&stamp) = self.in_flight.front() {
            if until.is_some_and(|t| stamp > t) {
                break;
            }
            self.in_flight.pop_front();
            match done.recv() {
                Ok(frame) => self.ready.push(frame),
                Err(_) => {
                    self.error.get_or_insert_with(|| WORKER_STOPPED.into());
                    self.in_flight.clear();
                }
            }
        }
    }

    /// Whether a frame of `robot` taken at `stamp` is to be recorded.
    fn due(&self, robot: RobotIndex, stamp: f64) -> bool {
        let last = self.last.get(robot.0 as usize).copied().flatten();
        last.is_none_or(|last| stamp >= last + self.period - 1e-9)
    }

    /// Sends a due frame to the worker.
    fn submit(&mut self, job: Job) {
        let i = job.robot.0 as usize;
        if self.last.len() <= i {
            self.last.resize(i + 1, None);
        }
        let stamp = job.frame.stamp;
        self.last[i] = Some(stamp);
        let Some(jobs) = &self.jobs else { return };
        if jobs.send(job).is_ok() {
            self.in_flight.push_back(stamp);
        } else {
            self.error.get_or_insert_with(|| WORKER_STOPPED.into());
        }
    }

    /// What the recorders want of each frame.
    pub fn outputs(&self) -> FrameOutputs {
        self.outputs
    }

    /// The run is over: the frames still being rendered, oldest first; the worker ends.
    pub fn finish(mut self) -> (Vec<RecordedFrame>, Option<String>) {
        self.ready.clear();
        self.jobs = None;
        self.collect(None);
        if let Some(w) = self.worker.take()
            && w.join().is_err()
        {
            self.error
                .get_or_insert_with(|| "the camera frame worker panicked".into());
        }
        (std::mem::take(&mut self.ready), self.error.take())
    }
}

/// The camera frames of the recordings as a plugin of the tick: [`collect_frames`] in the Record
/// set, then (for the .rrd) [`record_frames_rrd`] after the .rrd's other recorders. The MCAP
/// writer, built after this plugin, orders itself between the two
/// ([`crate::record::topics::McapPlugin`]).
pub struct FramesPlugin {
    frames: Cell<Option<RecordedFrames>>,
}

impl FramesPlugin {
    /// Starts the frame worker when a robot of `world` carries a camera and a recording wants
    /// frames (None otherwise). `camera_rate`: recorded frames per second and camera.
    pub fn new(
        world: &mut World,
        camera_rate: f64,
        outputs: FrameOutputs,
    ) -> anyhow::Result<Option<Self>> {
        let cameras = world.query::<&Camera>().iter(world).count();
        if cameras == 0 || !(outputs.raw || outputs.jpeg) {
            return Ok(None);
        }
        Ok(Some(FramesPlugin {
            frames: Cell::new(Some(RecordedFrames::new(camera_rate, outputs)?)),
        }))
    }
}

impl SimPlugin for FramesPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        let frames = self.frames.take().expect("FramesPlugin is built once");
        let jpeg = frames.outputs.jpeg;
        world.insert_resource(frames);
        let collect = collect_frames.in_set(SimSet::Record);
        // the .rrd's images after the frames are collected and after the .rrd's other
        // recorders (all write the recorder); JPEGs are made only for a .rrd
        #[cfg(feature = "rrd")]
        if jpeg {
            let images = record_frames_rrd
                .in_set(SimSet::Record)
                .after(record_events);
            schedule.add_systems((collect, images).chain());
            return;
        }
        debug_assert!(!jpeg, "JPEG frames without a .rrd to take them");
        schedule.add_systems(collect);
    }
}

/// Renders (and encodes) one frame; on the worker thread.
fn render(job: Job, outputs: FrameOutputs) -> RecordedFrame {
    let (w, h) = (job.rays.width, job.rays.height);
    let mut image = CameraImage::new(w, h);
    image.stamp = job.frame.stamp;
    FrameView::new(
        &job.rays,
        job.frame.pose,
        &job.raster,
        &job.palette,
        job.frame.params,
    )
    .render_here(&mut image.rgb);
    // the detection is drawn on a copy only when the raw frame is kept as well
    let jpeg = outputs.jpeg.then(|| match &job.detection {
        Some(d) if outputs.raw => {
            let mut drawn = image.clone();
            draw_detection(&mut drawn, d);
            encode_jpeg(&drawn)
        }
        Some(d) => {
            draw_detection(&mut image, d);
            encode_jpeg(&image)
        }
        None => encode_jpeg(&image),
    });
    let raw = outputs.raw.then_some(image);
    RecordedFrame {
        robot: job.robot,
        name: job.name,
        stamp: job.frame.stamp,
        raw,
        jpeg,
    }
}

/// JPEG of an RGB8 image.
fn encode_jpeg(image: &CameraImage) -> Result<Vec<u8>, String> {
    let (Ok(w), Ok(h)) = (u16::try_from(image.width), u16::try_from(image.height)) else {
        return Err(format!(
            "a {}×{} image is too large for a JPEG",
            image.width, image.height
        ));
    };
    let mut out = Vec::new();
    rusty_jpeg::Encoder::new(&mut out, JPEG_QUALITY)
        .encode(&image.rgb, w, h, rusty_jpeg::ColorType::Rgb)
        .map_err(|e| format!("camera image: {e}"))?;
    Ok(out)
}

/// Record set, before the recorders: hands them the frames due this tick
/// ([`RecordedFrames::ready`]) and sends this tick's fresh frames to the worker.
pub fn collect_frames(
    clock: Res<SimClock>,
    frames: ResMut<RecordedFrames>,
    surface: Option<Res<RoadSurface>>,
    cameras: Query<(
        &RobotIndex,
        &RobotId,
        &Camera,
        &CameraImages,
        Option<&RoadDetector>,
    )>,
) {
    let frames = frames.into_inner();
    let now = clock.now();
    frames.ready.clear();
    frames.collect(Some(now - COLLECT_AFTER + 1e-9));
    let mut fresh: Vec<_> = cameras
        .iter()
        .filter(|(.., images, _)| images.fresh)
        .filter_map(|(i, id, camera, images, det)| Some((*i, id, camera, images.frame?, det)))
        .filter(|f| frames.due(f.0, f.3.stamp))
        .collect();
    fresh.sort_by_key(|f| f.0);
    let raster = surface.map_or_else(|| frames.grass.clone(), |s| s.0.clone());
    for (robot, id, camera, frame, det) in fresh {
        let detection = det
            .filter(|_| frames.outputs.jpeg)
            .and_then(|d| d.detection.clone());
        frames.submit(Job {
            robot,
            name: id.0.clone(),
            frame,
            rays: camera.rays.clone(),
            palette: camera.palette.clone(),
            raster: raster.clone(),
            detection,
        });
    }
}

/// Logs `frames` to the .rrd at `robots/<name>/camera` (taking their JPEGs), each at its own
/// time; the recording's time is `now` afterwards.
#[cfg(feature = "rrd")]
pub fn log_frames_rrd(r: &mut RrdRecorder, frames: &mut [RecordedFrame], now: f64) {
    for f in frames {
        let Some(jpeg) = f.jpeg.take() else { continue };
        match jpeg {
            Ok(bytes) => {
                r.rec.set_duration_secs("sim_time", f.stamp);
                let res = r.rec.log(
                    format!("robots/{}/camera", f.name),
                    &rerun::EncodedImage::from_file_contents(bytes)
                        .with_media_type(rerun::MediaType::JPEG),
                );
                r.check(res);
            }
            Err(e) => {
                r.error.get_or_insert(e);
            }
        }
    }
    r.rec.set_duration_secs("sim_time", now);
}

/// Record set, after [`collect_frames`]: the .rrd's camera images.
#[cfg(feature = "rrd")]
pub fn record_frames_rrd(
    clock: Res<SimClock>,
    mut frames: ResMut<RecordedFrames>,
    mut r: ResMut<RrdRecorder>,
) {
    if !frames.ready.is_empty() {
        log_frames_rrd(&mut r, &mut frames.ready, clock.now());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use systems::body::TruePose;
    use systems::core::{Pose2, stream_rng};
    use systems::sensors::camera::{CameraSpec, sample_cameras};

    /// Two cameras on grass, 10 Hz each, frames recorded at 2 Hz for `secs` of 50 ms ticks:
    /// the frames handed over per tick (tick time, robot, stamp) and those left at the end.
    fn record(secs: f64, outputs: FrameOutputs) -> (Vec<(f64, u32, f64)>, Vec<RecordedFrame>) {
        let mut world = World::new();
        world.insert_resource(SimClock::new(0.05));
        world.insert_resource(RecordedFrames::new(2.0, outputs).unwrap());
        for (i, name) in ["a", "b"].into_iter().enumerate() {
            world.spawn((
                RobotIndex(i as u32),
                RobotId(name.into()),
                TruePose::at(Pose2::new(i as f64, 0.0, 0.3)),
                Camera::new(CameraSpec::default(), stream_rng(4, name, "camera")),
                CameraImages::default(),
            ));
        }
        let mut schedule = Schedule::default();
        schedule.add_systems((sample_cameras, collect_frames).chain());
        let mut handed = Vec::new();
        for _ in 0..(secs / 0.05).round() as usize {
            schedule.run(&mut world);
            let now = world.resource::<SimClock>().now();
            for f in &world.resource::<RecordedFrames>().ready {
                handed.push((now, f.robot.0, f.stamp));
            }
            world.resource_mut::<SimClock>().advance();
        }
        let (rest, error) = world.remove_resource::<RecordedFrames>().unwrap().finish();
        assert_eq!(error, None);
        (handed, rest)
    }

    #[test]
    fn frames_come_at_the_record_rate_collect_after_they_were_taken() {
        let outputs = FrameOutputs {
            raw: true,
            jpeg: false,
        };
        let end = COLLECT_AFTER + 2.0;
        let (handed, rest) = record(end, outputs);
        // ticks end at 0.05 ... `end`; frames every 0.5 s from 0 for each robot, robot order
        // within a tick; handed over in the first tick at least COLLECT_AFTER later, those of
        // the last COLLECT_AFTER seconds at the end
        let frames = |from: f64, to: f64| -> Vec<(u32, f64)> {
            (0..=(end * 2.0).round() as usize)
                .map(|k| k as f64 * 0.5)
                .filter(|t| *t >= from - 1e-9 && *t <= to + 1e-9)
                .flat_map(|t| [(0, t), (1, t)])
                .collect()
        };
        let same = |got: &[(u32, f64)], want: &[(u32, f64)]| {
            assert_eq!(got.len(), want.len(), "{got:?}");
            for ((r, t), (wr, wt)) in got.iter().zip(want) {
                assert_eq!(r, wr);
                assert!((t - wt).abs() < 1e-9, "{got:?}");
            }
        };
        let stamps: Vec<(u32, f64)> = handed.iter().map(|h| (h.1, h.2)).collect();
        same(&stamps, &frames(0.0, 2.0));
        for (now, _, stamp) in &handed {
            assert!(now - stamp >= COLLECT_AFTER - 1e-9 && now - stamp < COLLECT_AFTER + 0.05);
        }
        let left: Vec<(u32, f64)> = rest.iter().map(|f| (f.robot.0, f.stamp)).collect();
        same(&left, &frames(2.5, end));
        assert!(rest.iter().all(|f| f.raw.is_some() && f.jpeg.is_none()));
    }

    #[test]
    fn a_recorded_frame_is_the_cameras_image_and_its_jpeg_decodes_to_it() {
        let outputs = FrameOutputs {
            raw: true,
            jpeg: true,
        };
        let (_, rest) = record(0.05, outputs);
        let f = &rest[0];
        // the same draws: a camera of the same stream takes the same frame
        let mut cam = Camera::new(CameraSpec::default(), stream_rng(4, "a", "camera"));
        let frame = cam.take(0.0, Pose2::new(0.0, 0.0, 0.3));
        let want = cam.render(&frame, &SurfaceRaster::empty());
        assert_eq!(f.raw.as_ref().unwrap(), &want);
        let jpeg = f.jpeg.as_ref().unwrap().as_ref().unwrap();
        let decoded = image::load_from_memory_with_format(jpeg, image::ImageFormat::Jpeg)
            .unwrap()
            .to_rgb8();
        assert_eq!(decoded.dimensions(), (want.width, want.height));
        // no road detection drawn on grass: the JPEG is the frame up to compression
        let diff = decoded
            .as_raw()
            .iter()
            .zip(&want.rgb)
            .map(|(&a, &b)| (a as f64 - b as f64).abs())
            .sum::<f64>()
            / want.rgb.len() as f64;
        assert!(diff < 8.0, "mean absolute difference {diff}");
    }
}
