use super::*;
use crate::core::{Pose2, stream_rng};
use crate::navigation::road_recognition::{RecognitionConfig, RoadRecognizer, draw_detection};
use crate::sensors::camera::{Camera, CameraImage};
use crate::world::roads::surface_raster::{is_road_class, park_fixture, park_pose};

/// A camera and a recognizer that learned the road colours at `learn`.
fn setup(learn: Pose2, seed: u64) -> (Camera, RoadRecognizer) {
    let raster = &park_fixture().1;
    let mut cam = Camera::new(CameraSpec::default(), stream_rng(seed, "r", "camera"));
    let mut rec = RoadRecognizer::new(RecognitionConfig::default());
    while rec.learning() {
        let img = cam.shoot(0.0, learn, raster);
        rec.process(&img);
    }
    (cam, rec)
}

fn steer_at(cam: &mut Camera, rec: &mut RoadRecognizer, pose: Pose2, keep: Keep) -> RoadCommand {
    let img = cam.shoot(1.0, pose, &park_fixture().1);
    let det = rec.process(&img);
    let params = RoadFollowParams {
        keep,
        ..RoadFollowParams::default()
    };
    road_steering(&cam.spec, &det, &params)
        .unwrap_or_else(|| panic!("no command at {pose:?}: {} rows", det.rows.len()))
}

/// Basilica Avenue (asphalt, 4 m), straight between OSM nodes 82 and 15.
fn basilica(left: f64, turn_deg: f64) -> Pose2 {
    let p = park_pose("82", "15", 4.0, left);
    Pose2::new(p.x, p.y, p.theta + turn_deg.to_radians())
}

#[test]
fn an_offset_robot_steers_back_to_the_centre() {
    let (mut cam, mut rec) = setup(basilica(0.0, 0.0), 1);
    let centred = steer_at(&mut cam, &mut rec, basilica(0.0, 0.0), Keep::Centre);
    assert!(centred.curvature.abs() < 0.05, "{centred:?}");
    // 1 m left of the centre: the road centre is to the right, turn right (clockwise)
    let left = steer_at(&mut cam, &mut rec, basilica(1.0, 0.0), Keep::Centre);
    assert!(left.yaw_rate(1.0) < -0.05, "{left:?}");
    assert!((left.target[1] + 1.0).abs() < 0.35, "{left:?}");
    let right = steer_at(&mut cam, &mut rec, basilica(-1.0, 0.0), Keep::Centre);
    assert!(right.yaw_rate(1.0) > 0.05, "{right:?}");
    assert!((right.target[1] - 1.0).abs() < 0.35, "{right:?}");
}

#[test]
fn a_heading_error_is_steered_out() {
    let (mut cam, mut rec) = setup(basilica(0.0, 0.0), 2);
    // turned 10° left of the road: turn right, and vice versa
    let ccw = steer_at(&mut cam, &mut rec, basilica(0.0, 10.0), Keep::Centre);
    assert!(ccw.yaw_rate(1.0) < -0.05, "{ccw:?}");
    let cw = steer_at(&mut cam, &mut rec, basilica(0.0, -10.0), Keep::Centre);
    assert!(cw.yaw_rate(1.0) > 0.05, "{cw:?}");
    // the target lies on the road's centre line: y = -x·tan(10°) in the robot frame
    let expect = -ccw.target[0] * 10f64.to_radians().tan();
    assert!((ccw.target[1] - expect).abs() < 0.35, "{ccw:?} vs {expect}");
}

#[test]
fn keeping_to_an_edge_pursues_a_point_inside_it() {
    let (mut cam, mut rec) = setup(basilica(0.0, 0.0), 3);
    let pose = basilica(0.0, 0.0);
    let left = steer_at(&mut cam, &mut rec, pose, Keep::Left(0.5));
    let right = steer_at(&mut cam, &mut rec, pose, Keep::Right(0.5));
    // the asphalt's edges are 1.85 m to each side; 0.5 m inside them
    assert!((left.target[1] - 1.35).abs() < 0.3, "{left:?}");
    assert!((right.target[1] + 1.35).abs() < 0.3, "{right:?}");
    assert!(left.curvature > 0.05 && right.curvature < -0.05);
}

#[test]
fn no_road_no_command() {
    let (mut cam, mut rec) = setup(basilica(0.0, 0.0), 4);
    let img = cam.shoot(1.0, basilica(20.0, 0.0), &park_fixture().1);
    let det = rec.process(&img);
    assert!(road_steering(&cam.spec, &det, &RoadFollowParams::default()).is_none());
    let empty = RoadDetection {
        rows: Vec::new(),
        ..det
    };
    assert!(road_steering(&cam.spec, &empty, &RoadFollowParams::default()).is_none());
}

/// Drives a unicycle at 1 m/s for `steps` steps of 0.1 s from `start`, steering by the camera;
/// returns the poses and fails if the robot leaves the road surface.
fn drive(start: Pose2, steps: usize, seed: u64, dump: Option<&str>) -> Vec<Pose2> {
    let raster = &park_fixture().1;
    let (mut cam, mut rec) = setup(start, seed);
    let params = RoadFollowParams::default();
    let (v, dt) = (1.0, 0.1);
    let mut pose = start;
    let mut img = CameraImage::new(cam.spec.width, cam.spec.height);
    let mut poses = vec![pose];
    for k in 0..steps {
        cam.capture(k as f64 * dt, pose, raster, &mut img);
        let det = rec.process(&img);
        let cmd = road_steering(&cam.spec, &det, &params);
        if let Some(dir) = dump.filter(|_| k % 50 == 0 || cmd.is_none()) {
            let mut drawn = img.clone();
            draw_detection(&mut drawn, &det);
            let path = format!("{dir}/follow_{k:03}.png");
            image::save_buffer(path, &drawn.rgb, 320, 240, image::ExtendedColorType::Rgb8).unwrap();
        }
        let cmd =
            cmd.unwrap_or_else(|| panic!("step {k}: lost the road at {pose:?}: {:?}", det.rows));
        let w = cmd.yaw_rate(v);
        pose = Pose2::new(
            pose.x + v * dt * pose.theta.cos(),
            pose.y + v * dt * pose.theta.sin(),
            pose.theta + w * dt,
        );
        let class = raster.class_at(pose.x, pose.y);
        assert!(
            is_road_class(class),
            "step {k}: off the road at {pose:?} (class {class})"
        );
        poses.push(pose);
    }
    poses
}

#[test]
fn closed_loop_the_robot_follows_a_curved_road() {
    // Rampart Road (asphalt, 5 m) from OSM node 9 towards 10: it bends 36° to the right over
    // 58 m through shape points 61..65, with no junction
    let start = park_pose("9", "61", 2.0, 0.8);
    let dump = std::env::var("CAMERA_DUMP").ok();
    let poses = drive(start, 480, 7, dump.as_deref());
    let g = &park_fixture().0;
    let end = *poses.last().unwrap();
    // 48 m driven, ending near the centre line, heading along the road
    let e = g.nearest_edge([end.x, end.y]).unwrap();
    assert!(e.distance < 0.8, "{e:?} at {end:?}");
    let edge = &g.edges[e.edge];
    let (a, b) = (g.nodes[edge.a].pos, g.nodes[edge.b].pos);
    let along = (b[1] - a[1]).atan2(b[0] - a[0]);
    let err = crate::core::wrap_angle(end.theta - along);
    let err = err.abs().min(std::f64::consts::PI - err.abs());
    assert!(
        err < 8f64.to_radians(),
        "heading off by {}°",
        err.to_degrees()
    );
    // the robot turned with the road
    let turned = crate::core::wrap_angle(end.theta - start.theta).to_degrees();
    assert!((-40.0..-15.0).contains(&turned), "turned {turned}°");
    // the worst distance from the centre line on the way
    let worst = poses
        .iter()
        .map(|p| g.nearest_edge([p.x, p.y]).unwrap().distance)
        .fold(0.0, f64::max);
    assert!(worst < 1.2, "{worst}");
}

#[test]
fn closed_loop_the_robot_takes_the_bends_of_a_gravel_path() {
    // Bastion Walk (gravel, 3 m) from OSM node 127: bends of 15–56° at every shape point
    // (10 m apart), round the park's north-west corner to node 134
    let start = park_pose("127", "128", 1.0, 0.0);
    let poses = drive(start, 650, 8, None);
    let g = &park_fixture().0;
    let end = *poses.last().unwrap();
    let e = g.nearest_edge([end.x, end.y]).unwrap();
    let edge = &g.edges[e.edge];
    let ends = [&g.nodes[edge.a].source, &g.nodes[edge.b].source];
    assert!(
        ends.contains(&&"133".to_string()) && ends.contains(&&"134".to_string()),
        "ended on {ends:?} at {end:?}"
    );
    // heading south (the edge 133 → 134 runs at -84°)
    assert!((end.theta.to_degrees() + 84.0).abs() < 12.0, "{end:?}");
    let worst = poses
        .iter()
        .map(|p| g.nearest_edge([p.x, p.y]).unwrap().distance)
        .fold(0.0, f64::max);
    assert!(worst < 1.1, "{worst}");
}
