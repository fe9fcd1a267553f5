//! Camera on the park (assets/roads/park/park.osm): rendering one 320×240 frame from the
//! rasterized road surface (0.05 m cells) on Basilica Avenue, the thesis's road recognition of
//! one frame with learned colours ([Park thesis §5.2]: rows bottom-up with step 2,
//! pixels from the centre out with step 4, one 64³ table read per pixel) of a rendered frame
//! and of a frame whose pixels are computed as the recognizer reads them (what a run does),
//! the road follower on the detection, and the one-off rasterization of the park.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use systems::core::{Pose2, stream_rng};
use systems::navigation::road_follow::{RoadFollowParams, road_steering};
use systems::navigation::road_recognition::{RecognitionConfig, RoadRecognizer};
use systems::sensors::camera::{Camera, CameraSpec};
use systems::world::roads::surface_raster::{DEFAULT_MARGIN, DEFAULT_RESOLUTION};
use systems::world::roads::{RoadGraph, RoadOptions, SurfaceRaster, load_roads};

fn park() -> RoadGraph {
    let path = systems::core::source::source_path("assets/roads/park/park.osm");
    load_roads(&path, &RoadOptions::default()).unwrap()
}

/// 3 m from OSM node 82 towards node 15 on Basilica Avenue, heading along it.
fn pose_on_basilica(g: &RoadGraph) -> Pose2 {
    let a = g.nodes[g.node_by_source("82").unwrap()].pos;
    let b = g.nodes[g.node_by_source("15").unwrap()].pos;
    let yaw = (b[1] - a[1]).atan2(b[0] - a[0]);
    Pose2::new(a[0] + 3.0 * yaw.cos(), a[1] + 3.0 * yaw.sin(), yaw)
}

fn bench_camera(c: &mut Criterion) {
    let g = park();
    let raster = SurfaceRaster::build(&g, DEFAULT_RESOLUTION, DEFAULT_MARGIN);
    eprintln!(
        "park raster: {} × {} cells, {:.1} MB",
        raster.width,
        raster.height,
        raster.bytes() as f64 / 1e6
    );
    let pose = pose_on_basilica(&g);
    let mut cam = Camera::new(CameraSpec::default(), stream_rng(1, "bench", "camera"));
    let mut img = cam.shoot(0.0, pose, &raster);
    let mut rec = RoadRecognizer::new(RecognitionConfig::default());
    while rec.learning() {
        cam.capture(0.0, pose, &raster, &mut img);
        rec.process(&img);
    }
    let det = rec.recognize(&img);
    eprintln!(
        "{} learned colours, {} rows with road",
        rec.table.learned().len(),
        det.rows.len()
    );

    let mut grp = c.benchmark_group("camera_park");
    grp.bench_function("render_320x240", |b| {
        b.iter(|| cam.capture(0.0, black_box(pose), &raster, &mut img))
    });
    // a recorder's frame: the whole image on one thread
    let frame = cam.take(0.0, pose);
    let mut rgb = vec![0u8; img.rgb.len()];
    grp.bench_function("render_320x240_one_thread", |b| {
        b.iter(|| {
            cam.view(black_box(&frame), &raster)
                .pixels
                .render_here(&mut rgb)
        })
    });
    grp.bench_function("recognize_320x240", |b| {
        b.iter(|| black_box(rec.recognize(black_box(&img))))
    });
    // what a run does per frame: the recognizer computes only the pixels it reads
    grp.bench_function("take_and_recognize_320x240", |b| {
        b.iter(|| black_box(rec.recognize(&cam.view(black_box(&frame), &raster))))
    });
    let params = RoadFollowParams::default();
    grp.bench_function("road_steering", |b| {
        b.iter(|| black_box(road_steering(&cam.spec, black_box(&det), &params)))
    });
    grp.finish();

    let mut slow = c.benchmark_group("camera_setup");
    slow.sample_size(10);
    slow.bench_function("rasterize_park", |b| {
        b.iter(|| black_box(SurfaceRaster::build(&g, DEFAULT_RESOLUTION, DEFAULT_MARGIN)))
    });
    slow.finish();
}

criterion_group!(benches, bench_camera);
criterion_main!(benches);
