//! How to drive through a junction ([Park thesis §5.5]): at a node with more than two neighbours
//! the robot keeps to the left road edge when the next road is the leftmost of the roads leaving
//! the node, to the right edge when it is the rightmost, and otherwise steers by the compass
//! towards the next road's azimuth. Following an edge of the road round the junction takes the
//! outermost branch without knowing the junction's geometry exactly, which the GPS cannot give to a
//! metre.

use crate::core::wrap_angle;
use crate::world::roads::{EdgeId, NodeId, RoadGraph};

/// The manoeuvre for one junction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JunctionMove {
    /// Follow the left road edge (the next road is the leftmost).
    KeepLeft,
    /// Follow the right road edge (the next road is the rightmost).
    KeepRight,
    /// Steer by the compass to this azimuth (rad clockwise from north).
    Compass(f64),
}

/// The turn (rad, clockwise positive: to the right) from arriving along `azimuth_in` to leaving
/// along `azimuth_out`.
pub fn turn_angle(azimuth_in: f64, azimuth_out: f64) -> f64 {
    wrap_angle(azimuth_out - azimuth_in)
}

/// The move at `node` for a robot arriving on `from_edge` and leaving on `next_edge`. At a node
/// of degree two or less (a bend) the road itself leads on: the camera follows it, which is
/// returned as the compass move along the next edge for the case the camera loses the road.
pub fn junction_move(
    graph: &RoadGraph,
    node: NodeId,
    from_edge: EdgeId,
    next_edge: EdgeId,
) -> JunctionMove {
    let from = &graph.edges[from_edge];
    let came_from = if from.a == node { from.b } else { from.a };
    // arriving azimuth: from the previous node towards this one
    let azimuth_in = graph.azimuth_from(from_edge, came_from);
    let azimuth_next = graph.azimuth_from(next_edge, node);
    let exits: Vec<f64> = graph.adjacency[node]
        .iter()
        .filter(|&&(e, _)| e != from_edge)
        .map(|&(e, _)| turn_angle(azimuth_in, graph.azimuth_from(e, node)))
        .collect();
    if exits.len() < 2 {
        return JunctionMove::Compass(azimuth_next);
    }
    let turn = turn_angle(azimuth_in, azimuth_next);
    let leftmost = exits.iter().copied().fold(f64::INFINITY, f64::min);
    let rightmost = exits.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if turn <= leftmost + 1e-9 {
        JunctionMove::KeepLeft
    } else if turn >= rightmost - 1e-9 {
        JunctionMove::KeepRight
    } else {
        JunctionMove::Compass(azimuth_next)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::roads::{RoadOptions, parse_roads};
    use std::path::Path;

    /// A four-way crossing at node "c" with arms north, east, south and west (OSM XML).
    fn crossing() -> RoadGraph {
        let mut xml = String::from("<osm version=\"0.6\">");
        // 0.0009° of latitude ≈ 100 m
        for (id, lat, lon) in [
            ("c", 50.0, 14.0),
            ("n", 50.0009, 14.0),
            ("s", 49.9991, 14.0),
            ("e", 50.0, 14.0014),
            ("w", 50.0, 13.9986),
        ] {
            xml += &format!("<node id=\"{id}\" lat=\"{lat}\" lon=\"{lon}\"/>");
        }
        for (i, (a, b)) in [("s", "c"), ("c", "n"), ("w", "c"), ("c", "e")]
            .iter()
            .enumerate()
        {
            xml += &format!(
                "<way id=\"{i}\"><nd ref=\"{a}\"/><nd ref=\"{b}\"/><tag k=\"highway\" v=\"path\"/></way>"
            );
        }
        xml += "</osm>";
        parse_roads(&xml, Path::new("crossing.osm"), &RoadOptions::default()).unwrap()
    }

    #[test]
    fn at_a_crossing_the_outer_roads_are_kept_to_and_straight_on_goes_by_compass() {
        let g = crossing();
        let id = |s: &str| g.node_by_source(s).unwrap();
        let c = id("c");
        let from = g.edge_between(id("s"), c).unwrap(); // arriving northwards
        let left = g.edge_between(c, id("w")).unwrap();
        let right = g.edge_between(c, id("e")).unwrap();
        let ahead = g.edge_between(c, id("n")).unwrap();
        assert_eq!(junction_move(&g, c, from, left), JunctionMove::KeepLeft);
        assert_eq!(junction_move(&g, c, from, right), JunctionMove::KeepRight);
        match junction_move(&g, c, from, ahead) {
            JunctionMove::Compass(az) => assert!(wrap_angle(az).abs() < 0.02, "{az}"),
            m => panic!("straight on should steer by compass, got {m:?}"),
        }
    }

    #[test]
    fn turn_angles_are_clockwise_positive() {
        use std::f64::consts::FRAC_PI_2;
        assert!((turn_angle(0.0, FRAC_PI_2) - FRAC_PI_2).abs() < 1e-12);
        assert!((turn_angle(0.1, 6.2) + (0.1 + std::f64::consts::TAU - 6.2)).abs() < 1e-9);
    }
}
