use super::submap::Submaps;
use crate::core::Pose2;
use crate::mapping::inverse_model::OccupancyParams;
use crate::sensors::LaserScan;

fn ring_scan() -> LaserScan {
    LaserScan {
        stamp: 0.0,
        angle_min: -std::f32::consts::PI,
        angle_increment: std::f32::consts::PI / 180.0,
        range_min: 0.1,
        range_max: 20.0,
        ranges: vec![3.0; 360],
    }
}

#[test]
fn two_submaps_are_active_and_the_older_finishes_when_full() {
    let mut s = Submaps::new(10, 0.05, 2, OccupancyParams::slam(), 0.05, 4);
    let scan = ring_scan();
    let mut finished = Vec::new();
    for node in 0..26 {
        let p = Pose2::new(0.1 * node as f64, 0.0, 0.0);
        finished.extend(s.insert(node, &p, &p, &scan));
    }
    // submaps start every 5 nodes (half of 10); the first finishes at node 9, the next at 14…
    assert_eq!(finished, vec![0, 1, 2, 3]);
    let starts: Vec<usize> = s.all.iter().map(|m| m.anchor).collect();
    assert_eq!(starts, vec![0, 5, 10, 15, 20, 25]);
    assert!(
        s.all[..4]
            .iter()
            .all(|m| m.finished() && m.nodes.len() == 10)
    );
    assert!(s.is_active(4) && s.is_active(5) && !s.is_active(3));
    // scans are matched against the older active submap, which holds more
    assert_eq!(s.all[4].nodes.len(), 6);
    assert!(s.matching().is_some());
}
