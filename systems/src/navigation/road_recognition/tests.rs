use super::*;
use crate::body::TruePose;
use crate::core::{Pose2, SimClock, stream_rng};
use crate::sensors::camera::{Camera, CameraSpec, sample_cameras};
use crate::world::roads::RoadSurface;
use crate::world::roads::surface_raster::{park_fixture, park_pose};

/// A recognizer that learned from `frames` frames at `pose`, the camera that took them, and a
/// fresh frame at `pose`.
fn learned_at(pose: Pose2, seed: u64) -> (RoadRecognizer, Camera, CameraImage) {
    let raster = &park_fixture().1;
    let mut cam = Camera::new(CameraSpec::default(), stream_rng(seed, "r", "camera"));
    let mut rec = RoadRecognizer::new(RecognitionConfig::default());
    let mut img = cam.shoot(0.0, pose, raster);
    while rec.learning() {
        let det = rec.process(&img);
        assert!(det.learning);
        cam.capture(0.0, pose, raster, &mut img);
    }
    (rec, cam, img)
}

#[test]
fn finds_the_straight_asphalt_road_its_centre_and_width() {
    // Basilica Avenue (asphalt, 4 m) between OSM nodes 82 and 15, straight for 32 m
    let pose = park_pose("82", "15", 3.0, 0.0);
    let (mut rec, _, img) = learned_at(pose, 1);
    let n = rec.table.learned().len();
    assert!((2..=64).contains(&n), "{n} colours learned");
    let det = rec.process(&img);
    assert!(!det.learning);
    let spec = CameraSpec::default();
    // from the bottom row up to near the horizon (row 46) with a row step of 2
    assert_eq!(det.rows[0].v, 239);
    assert!(det.rows.windows(2).all(|w| w[0].v == w[1].v + 2));
    let top = det.rows.last().unwrap().v as f64;
    assert!(top < spec.horizon_v() + 15.0, "stopped at row {top}");
    // the bottom rows see only road: the scan reaches both image borders
    let bottom = &det.rows[0];
    assert!(!bottom.left_edge && !bottom.right_edge, "{bottom:?}");
    assert!((bottom.centre - 160.0).abs() < 3.0, "{bottom:?}");
    // further up both edges are in view, symmetric about the centre column
    let both: Vec<&RoadRow> = det
        .rows
        .iter()
        .filter(|r| r.left_edge && r.right_edge)
        .collect();
    assert!(both.len() >= 10, "{} rows see both edges", both.len());
    assert!((both[0].centre - 160.0).abs() < 6.0, "{:?}", both[0]);
    // the 4 m road less its two 0.15 m verges (not road colour) is 3.7 m of asphalt
    let widths: Vec<f64> = both
        .iter()
        .map(|r| {
            let v = r.v as f64 + 0.5;
            let l = spec.ground_point(r.left, v).unwrap();
            let rt = spec.ground_point(r.right, v).unwrap();
            l[1] - rt[1]
        })
        .collect();
    let good = widths.iter().filter(|w| (**w - 4.0).abs() < 0.8).count();
    assert!(good * 5 >= widths.len() * 4, "widths {widths:?}");
    let mut sorted = widths.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    assert!((median - 3.7).abs() < 0.4, "median width {median}");
}

#[test]
fn the_learned_table_tells_asphalt_from_grass_in_the_image() {
    let pose = park_pose("82", "15", 3.0, 0.0);
    let (rec, _, img) = learned_at(pose, 2);
    let (_, raster) = park_fixture();
    let spec = CameraSpec::default();
    let (s, c) = pose.theta.sin_cos();
    let (mut asphalt, mut asphalt_ok, mut grass, mut grass_road) = (0, 0, 0, 0);
    for v in (spec.horizon_v().ceil() as u32 + 4..240).step_by(3) {
        for u in (0..320).step_by(3) {
            let g = spec.ground_point(u as f64 + 0.5, v as f64 + 0.5).unwrap();
            let w = [pose.x + c * g[0] - s * g[1], pose.y + s * g[0] + c * g[1]];
            let road = rec.table.is_road(img.pixel(u, v));
            match raster.class_at(w[0], w[1]) {
                1 => {
                    asphalt += 1;
                    asphalt_ok += usize::from(road);
                }
                0 => {
                    grass += 1;
                    grass_road += usize::from(road);
                }
                _ => {}
            }
        }
    }
    assert!(asphalt > 1000 && grass > 100, "{asphalt} {grass}");
    assert!(
        asphalt_ok as f64 > 0.95 * asphalt as f64,
        "{asphalt_ok} of {asphalt} asphalt pixels"
    );
    eprintln!("asphalt {asphalt_ok}/{asphalt} grass as road {grass_road}/{grass}");
    assert!(
        grass_road * 200 <= grass,
        "{grass_road} of {grass} grass pixels"
    );
}

#[test]
fn a_frame_of_grass_has_no_road() {
    let pose = park_pose("82", "15", 3.0, 0.0);
    let (rec, mut cam, _) = learned_at(pose, 3);
    let off = Pose2::new(pose.x, pose.y + 20.0, pose.theta);
    let raster = &park_fixture().1;
    let det = rec.recognize(&cam.shoot(1.0, off, raster));
    assert!(
        det.rows.is_empty(),
        "{:?}",
        &det.rows[..det.rows.len().min(3)]
    );
    // nothing learned: nothing is road
    let fresh = RoadRecognizer::new(RecognitionConfig::default());
    assert!(
        fresh
            .recognize(&cam.shoot(1.1, pose, raster))
            .rows
            .is_empty()
    );
}

#[test]
fn rows_follow_a_road_that_leaves_the_image_centre() {
    // 1.2 m right of the centre of the 4 m road, turned 12° to the right: the road runs
    // up and to the left in the image
    let base = park_pose("82", "15", 3.0, -1.2);
    let pose = Pose2::new(base.x, base.y, base.theta - 12f64.to_radians());
    let learn = park_pose("82", "15", 3.0, 0.0);
    let (mut rec, mut cam, _) = learned_at(learn, 4);
    let img = cam.shoot(1.0, pose, &park_fixture().1);
    let det = rec.recognize(&img);
    let spec = CameraSpec::default();
    let far = det.rows.last().unwrap();
    assert!(far.centre < 110.0, "{far:?}");
    assert!((far.v as f64) < spec.horizon_v() + 15.0, "{far:?}");
    // the thesis's rule, every row from the image centre, loses it where the centre column
    // leaves the road
    rec.config.scan_from = ScanStart::ImageCentre;
    let thesis = rec.recognize(&img);
    assert!(
        thesis.rows.len() < det.rows.len(),
        "{} {}",
        thesis.rows.len(),
        det.rows.len()
    );
}

#[test]
fn the_drawing_marks_edges_and_centre() {
    let pose = park_pose("82", "15", 3.0, 0.0);
    let (mut rec, _, img) = learned_at(pose, 5);
    let det = rec.process(&img);
    let mut drawn = img.clone();
    draw_detection(&mut drawn, &det);
    let row = det
        .rows
        .iter()
        .find(|r| r.left_edge && r.right_edge)
        .unwrap();
    assert_eq!(drawn.pixel(row.left as u32, row.v), [255, 0, 0]);
    assert_eq!(drawn.pixel(row.right as u32, row.v), [255, 0, 0]);
    assert_eq!(drawn.pixel(row.centre as u32, row.v), [255, 230, 0]);
    assert_eq!(drawn.pixel(5, 5), img.pixel(5, 5));
}

#[test]
fn the_system_detects_on_fresh_images_only() {
    let raster = &park_fixture().1;
    let mut world = World::new();
    world.insert_resource(SimClock::new(0.05));
    world.insert_resource(RoadSurface(raster.clone()));
    let e = world
        .spawn((
            TruePose::at(park_pose("82", "15", 3.0, 0.0)),
            Camera::new(CameraSpec::default(), stream_rng(6, "r", "camera")),
            CameraImages::default(),
            RoadDetector::new(RecognitionConfig::default()),
        ))
        .id();
    let mut schedule = Schedule::default();
    schedule.add_systems((sample_cameras, detect_roads).chain());
    let mut fresh = Vec::new();
    for _ in 0..14 {
        schedule.run(&mut world);
        let d = world.get::<RoadDetector>(e).unwrap();
        fresh.push(d.fresh);
        world.resource_mut::<SimClock>().advance();
    }
    // 10 Hz on 50 ms ticks: frames in ticks 0, 1, 3, 5, ... (8 frames)
    assert_eq!(fresh.iter().filter(|f| **f).count(), 8);
    assert!(!fresh[2] && fresh[3]);
    let d = world.get::<RoadDetector>(e).unwrap();
    assert!(!d.recognizer.learning());
    let det = d.detection.as_ref().unwrap();
    assert!(!det.learning && det.rows.len() > 40, "{}", det.rows.len());
    assert!((det.stamp - 0.7).abs() < 1e-9, "{}", det.stamp);
}

#[test]
fn a_robot_beside_the_road_still_finds_it_further_up_the_image() {
    // 2 m beyond the left edge of the 4 m asphalt avenue, parallel to it
    let (rec, mut cam, _) = learned_at(park_pose("82", "15", 3.0, 0.0), 5);
    let img = cam.shoot(0.0, park_pose("82", "15", 8.0, 4.0), &park_fixture().1);
    let det = rec.recognize(&img);
    assert!(det.rows.len() >= 5, "{} rows", det.rows.len());
    // the bottom rows see grass only; the road appears higher up, right of the centre
    let first = det.rows[0];
    assert!(first.v < 235, "{first:?}");
    assert!(first.centre > 200.0, "{first:?}");
    let spec = CameraSpec::default();
    let g = spec
        .ground_point(first.centre, first.v as f64 + 0.5)
        .unwrap();
    assert!(
        (-5.5..=-1.8).contains(&g[1]),
        "road centre at {g:?} (robot frame)"
    );
}

#[test]
fn relearning_waits_for_the_new_road_and_never_learns_grass() {
    let raster = &park_fixture().1;
    let (mut rec, mut cam, _) = learned_at(park_pose("82", "15", 3.0, 0.0), 6);
    // driving on asphalt teaches the background beside it
    for i in 0..10 {
        let img = cam.shoot(
            0.0,
            park_pose("82", "15", 4.0 + 0.5 * i as f64, 0.0),
            raster,
        );
        rec.process(&img);
    }
    assert!(rec.background.learned().len() >= 3);
    // asked to learn a new surface while standing on the grass: nothing is learned
    rec.relearn(5);
    let on_grass = park_pose("82", "15", 10.0, 6.0);
    let grass = cam.shoot(0.0, on_grass, raster);
    let below = |img: &CameraImage| img.pixel(160, 230);
    for _ in 0..10 {
        let img = cam.shoot(0.0, on_grass, raster);
        rec.process(&img);
    }
    assert!(rec.relearning());
    assert!(!rec.table.is_road(below(&grass)));
    // it gives up after its frame budget, still without grass
    for _ in 0..(super::RELEARN_BUDGET as usize) {
        let img = cam.shoot(0.0, on_grass, raster);
        rec.process(&img);
    }
    assert!(!rec.relearning());
    assert!(!rec.table.is_road(below(&grass)));
}

#[test]
fn relearning_on_a_new_road_learns_it() {
    // a recognizer that learned the gravel of Linden Path at the start, then the asphalt of the
    // avenue by relearning (no background learned yet: nothing beside the gravel had both
    // edges in view)
    let raster = &park_fixture().1;
    let (mut rec, mut cam, _) = learned_at(park_pose("15", "100", 6.0, 0.0), 7);
    let on_asphalt = park_pose("82", "15", 10.0, 0.0);
    let asphalt = cam.shoot(0.0, on_asphalt, raster);
    let below = |img: &CameraImage| img.pixel(160, 230);
    let was_road = rec.table.is_road(below(&asphalt));
    rec.relearn(5);
    for _ in 0..8 {
        let img = cam.shoot(0.0, on_asphalt, raster);
        rec.process(&img);
    }
    assert!(!rec.relearning());
    let img = cam.shoot(0.0, on_asphalt, raster);
    assert!(
        rec.table.is_road(below(&img)),
        "asphalt road before: {was_road}"
    );
    assert!(rec.recognize(&img).rows.len() > 40);
}
