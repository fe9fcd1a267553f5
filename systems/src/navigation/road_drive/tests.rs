//! The road navigator on the park graph with synthetic beliefs (no camera, no physics).

use super::*;
use crate::world::roads::surface_raster::park_fixture;

fn id(g: &RoadGraph, s: &str) -> NodeId {
    g.node_by_source(s).unwrap()
}

fn belief(g: &RoadGraph, from: &str, to: &str, remaining: f64) -> RoadStart {
    let (a, b) = (id(g, from), id(g, to));
    RoadStart {
        edge: g.edge_between(a, b).unwrap(),
        toward: b,
        remaining,
    }
}

fn input<'a>(
    now: f64,
    b: Option<RoadStart>,
    compass: Option<f64>,
    follow: &'a dyn Fn(FollowSide) -> Option<[f64; 2]>,
) -> RoadDriveInput<'a> {
    RoadDriveInput {
        now,
        dt: 0.05,
        belief: b,
        compass,
        odometer: now,
        front_range: f64::INFINITY,
        follow,
        learned: &[],
    }
}

#[test]
fn plans_without_a_u_turn_replans_off_the_route_and_arrives() {
    let g = &park_fixture().0;
    let none = |_: FollowSide| None;
    let mut nav = RoadNavigator::new(id(g, "10"), RoadNavParams::default());
    // at the short route's start, facing node 19 (away from the goal)
    let b = belief(g, "37", "19", 14.0);
    let az = g.azimuth_from(b.edge, id(g, "37"));
    let (v, _) = nav.step(g, &input(0.0, Some(b), Some(az), &none));
    assert!(v > 0.0);
    let planned = nav.route.as_ref().unwrap().length;
    assert!((planned - 190.2).abs() < 6.0, "no U-turn: {planned:.1} m");
    assert_eq!(nav.stats.plans, 1);
    // the belief says the robot took the avenue west at 19 (not on the route): re-plan
    let wrong = belief(g, "19", "18", 10.0);
    nav.step(g, &input(20.0, Some(wrong), Some(az), &none));
    assert_eq!(nav.stats.replans, 1);
    assert!(nav.route_edges().contains(&wrong.edge));
    // near the goal: stop
    let last = *nav.route.as_ref().unwrap().edges.last().unwrap();
    let near = RoadStart {
        edge: last,
        toward: id(g, "10"),
        remaining: 1.0,
    };
    let (v, w) = nav.step(g, &input(300.0, Some(near), Some(az), &none));
    assert_eq!((v, w), (0.0, 0.0));
    assert_eq!(nav.phase, RoadPhase::Arrived);
    assert_eq!(nav.stats.arrived_at, Some(300.0));
}

#[test]
fn stops_at_the_goal_or_just_past_it_but_not_when_starting_past_it() {
    let g = &park_fixture().0;
    let none = |_: FollowSide| None;
    let goal = id(g, "10");
    let mut nav = RoadNavigator::new(goal, RoadNavParams::default());
    let b = belief(g, "37", "19", 14.0);
    let az = g.azimuth_from(b.edge, id(g, "37"));
    nav.step(g, &input(0.0, Some(b), Some(az), &none));
    let last = *nav.route.as_ref().unwrap().edges.last().unwrap();
    // an edge on from the goal, off the route
    let on = (0..g.edges.len())
        .find(|&e| e != last && (g.edges[e].a == goal || g.edges[e].b == goal))
        .unwrap();
    let past = |by: f64| RoadStart {
        edge: on,
        toward: other_end(g, on, goal),
        remaining: g.edges[on].length - by,
    };
    // 2 m before the goal the robot drives on (the default tolerance is 1 m)
    let approach = RoadStart {
        edge: last,
        toward: goal,
        remaining: 2.0,
    };
    let (v, _) = nav.step(g, &input(200.0, Some(approach), Some(az), &none));
    assert!(v > 0.0 && nav.phase != RoadPhase::Arrived);
    // an update moves the belief 0.5 m past the goal: there
    nav.step(g, &input(201.0, Some(past(0.5)), Some(az), &none));
    assert_eq!(nav.phase, RoadPhase::Arrived);

    // a robot that starts just past the goal, leaving it, has not arrived
    let mut nav = RoadNavigator::new(goal, RoadNavParams::default());
    let start = past(0.5);
    let az = g.azimuth_from(start.edge, goal);
    nav.step(g, &input(0.0, Some(start), Some(az), &none));
    assert_ne!(nav.phase, RoadPhase::Arrived);
}

#[test]
fn the_map_leads_where_the_camera_disagrees_with_the_route() {
    let g = &park_fixture().0;
    let mut nav = RoadNavigator::new(id(g, "10"), RoadNavParams::default());
    let b = belief(g, "37", "19", 10.0);
    let az = g.azimuth_from(b.edge, id(g, "37"));
    // the camera sees the road straight ahead: followed (no turn)
    let ahead = |_: FollowSide| Some([3.0, 0.0]);
    let (_, w) = nav.step(g, &input(0.0, Some(b), Some(az), &ahead));
    assert!(w.abs() < 1e-9);
    // the camera pulls hard left (another road): the map pursuit along the edge wins
    let left = |_: FollowSide| Some([1.0, 3.0]);
    let (_, w) = nav.step(g, &input(0.1, Some(b), Some(az), &left));
    assert!(w.abs() < 0.05, "followed the camera off the route: ω = {w}");
    // the road 3 m to the right, 5 m ahead (the robot has drifted off it): the camera leads
    let right = |_: FollowSide| Some([5.0, -3.0]);
    let (_, w) = nav.step(g, &input(0.2, Some(b), Some(az), &right));
    assert!(w < -0.1, "did not steer back to the road: ω = {w}");
}

#[test]
fn a_dead_end_makes_the_robot_turn_round() {
    let g = &park_fixture().0;
    let none = |_: FollowSide| None;
    // driving towards the West Gate (a dead end) with the goal behind
    let mut nav = RoadNavigator::new(id(g, "20"), RoadNavParams::default());
    let (a, gate) = (g.adjacency[id(g, "13")][0].1, id(g, "13"));
    let b = RoadStart {
        edge: g.edge_between(a, gate).unwrap(),
        toward: gate,
        remaining: 1.0,
    };
    let az = g.azimuth_from(b.edge, a);
    nav.step(g, &input(0.0, Some(b), Some(az), &none));
    assert!(
        matches!(nav.phase, RoadPhase::TurningRound { .. }),
        "{:?}",
        nav.phase
    );
    let (v, w) = nav.step(g, &input(0.1, Some(b), Some(az), &none));
    assert!(v > 0.0 && w.abs() > 0.0, "turning on full lock");
    // facing back: done
    let back = (az + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU);
    // the localizers follow the turn (the wiring drops estimates the compass contradicts)
    let reversed = RoadStart {
        toward: a,
        remaining: g.edges[b.edge].length - 1.0,
        ..b
    };
    nav.step(g, &input(5.0, Some(reversed), Some(back), &none));
    assert!(!matches!(nav.phase, RoadPhase::TurningRound { .. }));
}
