use super::*;
use crate::core::stream_rng;
use crate::world::roads::surface_raster::{park_fixture, park_pose};

#[test]
fn ground_point_and_pixel_of_are_inverse() {
    let spec = CameraSpec::default();
    let hz = spec.horizon_v();
    // the horizon is a third of the image from the top: 15° pitch in a 46.8° vertical view
    assert!((hz - (120.0 - spec.focal() * 15f64.to_radians().tan())).abs() < 1e-9);
    assert!((40.0..55.0).contains(&hz), "{hz}");
    for v in [hz + 0.5, hz + 3.0, 100.0, 180.0, 239.5] {
        for u in [0.0, 37.5, 160.0, 251.0, 320.0] {
            let g = spec.ground_point(u, v).unwrap();
            let back = spec.pixel_of(g).unwrap();
            assert!(
                (back[0] - u).abs() < 1e-6 && (back[1] - v).abs() < 1e-6,
                "({u}, {v}) → {g:?} → {back:?}"
            );
        }
    }
    assert!(spec.ground_point(160.0, hz - 0.5).is_none());
    assert!(spec.ground_point(10.0, 0.0).is_none());
    // straight ahead is on the centre column, further away is higher up
    let near = spec.pixel_of([2.0, 0.0]).unwrap();
    let far = spec.pixel_of([8.0, 0.0]).unwrap();
    assert!((near[0] - 160.0).abs() < 1e-9 && (far[0] - 160.0).abs() < 1e-9);
    assert!(far[1] < near[1] && far[1] > hz);
    // left of the robot is left in the image
    assert!(spec.pixel_of([3.0, 0.5]).unwrap()[0] < 160.0);
    // the bottom row sees the ground about 0.8 m ahead of the origin
    let bottom = spec.ground_point(160.0, 240.0).unwrap();
    assert!((0.6..1.0).contains(&bottom[0]), "{bottom:?}");
    // behind the camera there is no pixel
    assert!(spec.pixel_of([-1.0, 0.0]).is_none());
}

#[test]
fn rays_start_below_the_horizon() {
    let spec = CameraSpec::default();
    let rays = GroundRays::new(&spec);
    let first = rays.first_ground_row as f64;
    assert!(first + 0.5 > spec.horizon_v() && first - 0.5 <= spec.horizon_v() + 1.0);
    assert_eq!(
        rays.offsets.len(),
        (320 * (240 - rays.first_ground_row)) as usize
    );
    // the bottom-centre ray is the ground point of that pixel
    let g = spec.ground_point(160.5, 239.5).unwrap();
    let r = rays.offsets[rays.offsets.len() - 160];
    assert!((r[0] as f64 - g[0]).abs() < 1e-5 && (r[1] as f64 - g[1]).abs() < 1e-5);
}

fn mean_colour(img: &CameraImage, u: std::ops::Range<u32>, v: std::ops::Range<u32>) -> [f64; 3] {
    let mut s = [0.0; 3];
    let mut n = 0.0;
    for y in v {
        for x in u.clone() {
            let p = img.pixel(x, y);
            for k in 0..3 {
                s[k] += p[k] as f64;
            }
            n += 1.0;
        }
    }
    s.map(|c| c / n)
}

#[test]
fn the_road_ahead_is_grey_and_the_verges_green() {
    let (_, raster) = park_fixture();
    let spec = CameraSpec {
        brightness_std: 0.0,
        ..CameraSpec::default()
    };
    let mut cam = Camera::new(spec.clone(), stream_rng(1, "r", "camera"));
    // Basilica Avenue (asphalt, 4 m), heading along it, on its centre line
    let pose = park_pose("82", "15", 3.0, 0.0);
    let img = cam.shoot(0.0, pose, raster);
    if let Ok(dir) = std::env::var("CAMERA_DUMP") {
        image::save_buffer(
            format!("{dir}/camera_basilica.png"),
            &img.rgb,
            320,
            240,
            image::ExtendedColorType::Rgb8,
        )
        .unwrap();
    }
    assert_eq!(img.rgb.len(), 320 * 240 * 3);
    // bottom centre: asphalt (92, 92, 96)
    let road = mean_colour(&img, 140..180, 200..240);
    assert!(road.iter().all(|c| (c - 94.0).abs() < 8.0), "road {road:?}");
    // 6 m ahead the 4 m road spans ±2 m: 2.4 m to the left is grass (green)
    let [u, v] = spec.pixel_of([6.0, 2.4]).unwrap();
    let grass = mean_colour(&img, u as u32 - 3..u as u32 + 3, v as u32 - 2..v as u32 + 2);
    assert!(
        grass[1] > grass[0] + 20.0 && grass[1] > grass[2] + 40.0,
        "grass {grass:?}"
    );
    // the top row is sky (blue)
    let sky = mean_colour(&img, 0..320, 0..2);
    assert!(sky[2] > sky[0] + 40.0, "sky {sky:?}");
}

#[test]
fn same_seed_same_image() {
    let (_, raster) = park_fixture();
    let pose = park_pose("82", "15", 3.0, 0.5);
    let shoot = |seed: u64| {
        let mut cam = Camera::new(CameraSpec::default(), stream_rng(seed, "r", "camera"));
        let a = cam.shoot(0.0, pose, raster);
        let b = cam.shoot(0.1, pose, raster);
        (a, b)
    };
    let (a, b) = shoot(5);
    let (a2, b2) = shoot(5);
    assert_eq!(a.rgb, a2.rgb);
    assert_eq!(b.rgb, b2.rgb);
    // noise and brightness change from frame to frame and with the seed
    assert_ne!(a.rgb, b.rgb);
    assert_ne!(a.rgb, shoot(6).0.rgb);
    // rows render in parallel: the image does not depend on the number of threads
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let (a3, b3) = pool.install(|| shoot(5));
        assert_eq!(
            (a3.rgb, b3.rgb),
            (a.rgb.clone(), b.rgb.clone()),
            "{threads} threads"
        );
    }
    // ... nor on whether it is rendered on the calling thread alone
    let mut cam = Camera::new(CameraSpec::default(), stream_rng(5, "r", "camera"));
    let frame = cam.take(0.0, pose);
    let mut here = vec![0; a.rgb.len()];
    cam.view(&frame, raster).pixels.render_here(&mut here);
    assert_eq!(here, a.rgb);
}

#[test]
fn the_system_takes_the_last_frame_due_and_sees_grass_without_roads() {
    let mut world = World::new();
    world.insert_resource(SimClock::new(0.05));
    let spec = CameraSpec::default();
    let e = world
        .spawn((
            TruePose::at(Pose2::new(0.0, 0.0, 0.0)),
            Camera::new(spec, stream_rng(3, "r", "camera")),
            CameraImages::default(),
        ))
        .id();
    let mut schedule = Schedule::default();
    schedule.add_systems(sample_cameras);
    let mut fresh = Vec::new();
    for _ in 0..6 {
        schedule.run(&mut world);
        let out = world.get::<CameraImages>(e).unwrap();
        fresh.push(out.fresh);
        if out.fresh {
            let frame = out.frame.as_ref().unwrap();
            let t = world.resource::<SimClock>().now();
            assert!((frame.stamp - (t - 0.05)).abs() < 1e-9 || (frame.stamp - t).abs() < 1e-9);
        }
        world.resource_mut::<SimClock>().advance();
    }
    // 10 Hz on 50 ms ticks: t = 0 in the first tick, then 0.1, 0.2 at the ends of ticks 2, 4
    assert_eq!(fresh, [true, true, false, true, false, true]);
    let frame = world.get::<CameraImages>(e).unwrap().frame.unwrap();
    let empty = SurfaceRaster::empty();
    let img = world
        .get::<Camera>(e)
        .unwrap()
        .render(&frame, surface_or_grass(None, &empty));
    let ground = mean_colour(&img, 0..320, 120..240);
    assert!(ground[1] > ground[0] + 20.0, "grass everywhere {ground:?}");

    // a disabled camera takes no frame when one is due (t = 0.4 in the second tick)
    world.get_mut::<Camera>(e).unwrap().enabled = false;
    for _ in 0..2 {
        schedule.run(&mut world);
        assert!(!world.get::<CameraImages>(e).unwrap().fresh);
        world.resource_mut::<SimClock>().advance();
    }
    let stamp = world.get::<CameraImages>(e).unwrap().frame.unwrap().stamp;
    assert!((stamp - 0.3).abs() < 1e-9, "{stamp}");
}

#[test]
fn pixels_read_one_by_one_equal_the_rendered_image() {
    let (_, raster) = park_fixture();
    let mut cam = Camera::new(CameraSpec::default(), stream_rng(9, "r", "camera"));
    // on the road and beside it: road, verges, grass and sky
    for pose in [
        park_pose("82", "15", 3.0, 0.0),
        park_pose("82", "15", 8.0, 4.0),
    ] {
        let frame = cam.take(0.0, pose);
        let img = cam.render(&frame, raster);
        let view = cam.view(&frame, raster);
        assert_eq!((Pixels::width(&view), Pixels::height(&view)), (320, 240));
        for v in 0..240 {
            for u in 0..320 {
                assert_eq!(view.pixel(u, v), img.pixel(u, v), "pixel ({u}, {v})");
            }
        }
    }
}

#[test]
fn whole_rows_with_and_without_avx2_are_the_same_bytes() {
    let (_, park) = park_fixture();
    // a small raster, so that cameras see its edges, its last cells and beyond
    let small = {
        let mut r = SurfaceRaster::empty();
        (r.width, r.height, r.resolution) = (37, 23, 0.05);
        r.cells = (0..r.width * r.height).map(|k| (k % 8) as u8).collect();
        r
    };
    let odd = CameraSpec {
        width: 317,
        height: 61,
        ..CameraSpec::default()
    };
    let mut checked = 0;
    for (spec, raster) in [
        (CameraSpec::default(), park.as_ref()),
        (odd, park.as_ref()),
        (CameraSpec::default(), &small),
    ] {
        for seed in 0..4 {
            let mut cam = Camera::new(spec.clone(), stream_rng(seed, "r", "camera"));
            let poses = [
                park_pose("82", "15", 3.0, 0.0),
                park_pose("82", "15", 8.0, 4.0),
                Pose2::new(1.2, 0.6, 2.5),
                Pose2::new(2.0, 1.0, -0.4),
                Pose2::new(-3.0, -2.0, 0.7),
                Pose2::new(1e12, 0.0, 0.0),
            ];
            for pose in poses {
                let frame = cam.take(0.0, pose);
                let view = cam.view(&frame, raster).pixels;
                let mut rows = vec![0; (spec.width * spec.height * 3) as usize];
                let mut portable = rows.clone();
                view.render_here(&mut rows);
                view.without_avx2().render_here(&mut portable);
                assert_eq!(rows, portable, "seed {seed}, pose {pose:?}");
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 3 * 4 * 6);
}
