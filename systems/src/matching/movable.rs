//! Free-standing compact objects in a scan — people, robots, carts — found and set aside before
//! matching. Such an object may move between two scans; in a corridor, where the walls fix
//! nothing along it, lining up a person who walked 1 m with the robot outscores the few wall
//! ends that fix the true shift (most of the improved matcher's wrong answers in the hospital
//! scans of `sim experiment de-match` slid along a corridor this way). Filtering the scan
//! points of people before matching is the approach of Hähnel, Schulz & Burgard, "Mobile robot
//! mapping in populated environments" (IROS 2002), who track people and drop their beams;
//! without tracking, we drop what looks like one: a run of consecutive points (in scan order,
//! successive points closer than `gap`) spanning less than `extent`, standing at least `jump`
//! in front of the points just before and after it. A static pillar of that size is dropped
//! too — the price of not knowing which objects move.

use super::judge::dist2;

/// What counts as a free-standing object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Movable {
    /// Largest gap (m) between successive points of one object.
    pub gap: f32,
    /// An object's end points are less than this apart (m).
    pub extent: f32,
    /// The points just before and after it are at least this much farther from the sensor (m).
    pub jump: f32,
}

/// For each point (sensor frame, scan order), whether it belongs to a free-standing object.
/// Runs at either end of the scan have no neighbour on one side and are never objects.
pub(crate) fn free_standing(points: &[[f32; 2]], m: &Movable) -> Vec<bool> {
    let n = points.len();
    let mut out = vec![false; n];
    let range = |p: [f32; 2]| p[0].hypot(p[1]);
    let mut i = 0;
    while i < n {
        let mut j = i;
        while j + 1 < n && dist2(points[j], points[j + 1]) <= m.gap * m.gap {
            j += 1;
        }
        if i > 0 && j + 1 < n && dist2(points[i], points[j]) < m.extent * m.extent {
            let farthest = points[i..=j]
                .iter()
                .map(|&p| range(p))
                .fold(0.0f32, f32::max);
            let behind = farthest + m.jump;
            if range(points[i - 1]) > behind && range(points[j + 1]) > behind {
                out[i..=j].fill(true);
            }
        }
        i = j + 1;
    }
    out
}

/// `points` without its free-standing objects; all of them if that would leave fewer than
/// `min_left` (a scan that sees nothing but people is matched as it is).
pub(crate) fn without_movable(points: &[[f32; 2]], m: &Movable, min_left: usize) -> Vec<[f32; 2]> {
    let mask = free_standing(points, m);
    let kept: Vec<[f32; 2]> = points
        .iter()
        .zip(&mask)
        .filter(|&(_, &moving)| !moving)
        .map(|(&p, _)| p)
        .collect();
    if kept.len() >= min_left {
        kept
    } else {
        points.to_vec()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const M: Movable = Movable {
        gap: 0.25,
        extent: 0.7,
        jump: 0.3,
    };

    /// A wall at x = 5 seen over ±40°, 0.5° apart, with a disc (centre, radius) in front of it.
    fn wall_scan(object: Option<([f32; 2], f32)>) -> Vec<[f32; 2]> {
        (-80..=80)
            .map(|k| {
                let a = (k as f32 * 0.5).to_radians();
                let u = [a.cos(), a.sin()];
                let mut r = 5.0 / u[0];
                if let Some((c, radius)) = object {
                    let along = u[0] * c[0] + u[1] * c[1];
                    let off2 = c[0] * c[0] + c[1] * c[1] - along * along;
                    if along > 0.0 && off2 < radius * radius {
                        r = r.min(along - (radius * radius - off2).sqrt());
                    }
                }
                [r * u[0], r * u[1]]
            })
            .collect()
    }

    #[test]
    fn a_person_in_front_of_a_wall_is_found_and_the_wall_is_not() {
        let scan = wall_scan(Some(([2.5, 0.3], 0.25)));
        let mask = free_standing(&scan, &M);
        let person: Vec<usize> = (0..scan.len()).filter(|&i| mask[i]).collect();
        assert!(person.len() >= 8, "person points {person:?}");
        for &i in &person {
            let p = scan[i];
            let d = (p[0] - 2.5).hypot(p[1] - 0.3);
            assert!((d - 0.25).abs() < 1e-3, "point {p:?} is not on the person");
        }
        // every wall point is kept
        assert_eq!(
            without_movable(&scan, &M, 3).len(),
            scan.len() - person.len()
        );
        assert!(free_standing(&wall_scan(None), &M).iter().all(|&m| !m));
    }

    #[test]
    fn objects_against_a_wall_at_the_scan_edge_or_too_long_stay() {
        // a pillar half in the wall (as along the hospital's main corridor): no jump behind it
        let close = wall_scan(Some(([5.05, 0.0], 0.3)));
        assert!(free_standing(&close, &M).iter().all(|&m| !m));
        // a wide object (a 1.2 m cart) is not compact
        let wide = wall_scan(Some(([2.5, 0.0], 0.6)));
        assert!(free_standing(&wide, &M).iter().all(|&m| !m));
        // a person covering the first beams: no neighbour on one side
        let edge = wall_scan(Some(([2.0, -1.68], 0.25)));
        assert!(free_standing(&edge, &M)[0..3].iter().all(|&m| !m));
        // too little left without the person: the scan is matched as it is
        let person = wall_scan(Some(([2.5, 0.0], 0.25)));
        assert!(without_movable(&person, &M, 3).len() < person.len());
        assert_eq!(
            without_movable(&person, &M, person.len()).len(),
            person.len()
        );
    }
}
