//! Route planning on the road graph ([Park thesis §5.4]): A* with edge length as cost and the
//! straight-line distance to the goal as heuristic, and the thesis's no-U-turn rule for a car-like
//! robot — the node behind the robot is unreachable from the start.
//!
//! The rule is enforced everywhere, not only at the start: the search runs over *directed*
//! edges (u → v), and from (u → v) it may continue on any edge at v except straight back to u.
//! A robot that cannot turn on the spot therefore never gets a route that needs one; a goal
//! behind it is reached round a loop (the thesis's 190 m run, where the planner chose a longer
//! path), and a goal that needs a U-turn whatever the route (down a dead end and back) is
//! reported unreachable rather than planned. The straight-line heuristic never overestimates a
//! route along straight edges, so the first route found is the shortest without U-turns.
//! Ties are broken by the lower directed-edge index: the same graph and query give the same
//! route.

use crate::world::roads::{EdgeId, NodeId, RoadGraph};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

pub use crate::world::roads::RoadStart;

/// A planned route.
#[derive(Clone, Debug, PartialEq)]
pub struct RoadRoute {
    /// The nodes to drive through, from the node ahead of the robot to the goal.
    pub nodes: Vec<NodeId>,
    /// The edges after the start edge, `nodes.len() − 1` of them.
    pub edges: Vec<EdgeId>,
    /// Length (m), including the rest of the start edge.
    pub length: f64,
}

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RoadPlanError {
    #[error("edge {edge} does not exist or does not end at node {toward}")]
    BadStart { edge: EdgeId, toward: NodeId },
    #[error("goal node {0} does not exist")]
    BadGoal(NodeId),
    #[error("goal node {goal} cannot be reached from edge {edge} without a U-turn")]
    Unreachable { edge: EdgeId, goal: NodeId },
}

#[derive(Clone, Copy, PartialEq)]
struct Open {
    f: f64,
    state: usize,
}

impl Eq for Open {}

impl Ord for Open {
    fn cmp(&self, o: &Self) -> Ordering {
        // reversed for the max-heap: lowest f first, then the lowest state
        o.f.total_cmp(&self.f).then(o.state.cmp(&self.state))
    }
}

impl PartialOrd for Open {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// Directed edge `2·e` runs a → b, `2·e + 1` runs b → a.
fn directed(graph: &RoadGraph, edge: EdgeId, to: NodeId) -> usize {
    2 * edge + usize::from(graph.edges[edge].a == to)
}

fn head(graph: &RoadGraph, state: usize) -> NodeId {
    let e = &graph.edges[state / 2];
    if state.is_multiple_of(2) { e.b } else { e.a }
}

fn tail(graph: &RoadGraph, state: usize) -> NodeId {
    let e = &graph.edges[state / 2];
    if state.is_multiple_of(2) { e.a } else { e.b }
}

/// The shortest route from `start` to `goal` that never turns back along the edge it arrived on.
pub fn plan_route(
    graph: &RoadGraph,
    start: RoadStart,
    goal: NodeId,
) -> Result<RoadRoute, RoadPlanError> {
    let bad_start = RoadPlanError::BadStart {
        edge: start.edge,
        toward: start.toward,
    };
    let e = graph.edges.get(start.edge).ok_or(bad_start.clone())?;
    if e.a != start.toward && e.b != start.toward {
        return Err(bad_start);
    }
    if goal >= graph.nodes.len() {
        return Err(RoadPlanError::BadGoal(goal));
    }
    let g0 = start.remaining.max(0.0);
    if start.toward == goal {
        return Ok(RoadRoute {
            nodes: vec![goal],
            edges: Vec::new(),
            length: g0,
        });
    }
    let goal_pos = graph.nodes[goal].pos;
    let h = |n: NodeId| {
        let p = graph.nodes[n].pos;
        (p[0] - goal_pos[0]).hypot(p[1] - goal_pos[1])
    };
    let states = 2 * graph.edges.len();
    let mut g = vec![f64::INFINITY; states];
    let mut parent = vec![usize::MAX; states];
    let mut closed = vec![false; states];
    let mut open = BinaryHeap::new();
    let s0 = directed(graph, start.edge, start.toward);
    g[s0] = g0;
    open.push(Open {
        f: g0 + h(start.toward),
        state: s0,
    });
    while let Some(Open { state, .. }) = open.pop() {
        if std::mem::replace(&mut closed[state], true) {
            continue;
        }
        let v = head(graph, state);
        if v == goal {
            let mut chain = vec![state];
            while let Some(&p) = chain.last().map(|&s| &parent[s]) {
                if p == usize::MAX {
                    break;
                }
                chain.push(p);
            }
            chain.reverse();
            let mut nodes = vec![start.toward];
            nodes.extend(chain.iter().skip(1).map(|&s| head(graph, s)));
            return Ok(RoadRoute {
                nodes,
                edges: chain.iter().skip(1).map(|&s| s / 2).collect(),
                length: g[state],
            });
        }
        let came_from = tail(graph, state);
        for &(edge, w) in &graph.adjacency[v] {
            // the no-U-turn rule: not straight back along the edge just driven
            if edge == state / 2 && w == came_from {
                continue;
            }
            let next = directed(graph, edge, w);
            let cost = g[state] + graph.edges[edge].length;
            if cost < g[next] {
                g[next] = cost;
                parent[next] = state;
                open.push(Open {
                    f: cost + h(w),
                    state: next,
                });
            }
        }
    }
    Err(RoadPlanError::Unreachable {
        edge: start.edge,
        goal,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::roads::{GeoPoint, LocalProjection, Road, RoadNode, Surface};

    /// A graph from node positions and roads (lists of node indices).
    fn graph(pos: &[[f64; 2]], roads: &[&[usize]]) -> RoadGraph {
        let nodes = pos
            .iter()
            .enumerate()
            .map(|(i, &p)| RoadNode {
                pos: p,
                source: i.to_string(),
            })
            .collect();
        let roads = roads
            .iter()
            .map(|r| Road {
                name: String::new(),
                kind: "path".into(),
                surface: Surface::Gravel,
                width: 3.0,
                nodes: r.to_vec(),
            })
            .collect();
        let proj = LocalProjection::new(GeoPoint::new(50.0, 14.0)).unwrap();
        RoadGraph::build(proj, nodes, roads)
    }

    /// A 100 m × 50 m loop 0-1-2-3 with a spur 1-4 (dead end) and a cross road 0-2 through 5.
    ///
    /// ```text
    ///  3 ──────── 2
    ///  │        ╱ │
    ///  │     5    │
    ///  │   ╱      │
    ///  0 ──────── 1 ── 4
    /// ```
    fn park() -> RoadGraph {
        graph(
            &[
                [0.0, 0.0],
                [100.0, 0.0],
                [100.0, 50.0],
                [0.0, 50.0],
                [130.0, 0.0],
                [50.0, 25.0],
            ],
            &[&[0, 1, 2, 3, 0], &[1, 4], &[0, 5, 2]],
        )
    }

    fn start(g: &RoadGraph, from: NodeId, to: NodeId, remaining: f64) -> RoadStart {
        RoadStart {
            edge: g.edge_between(from, to).unwrap(),
            toward: to,
            remaining,
        }
    }

    #[test]
    fn a_goal_ahead_takes_the_shortest_way() {
        let g = park();
        let r = plan_route(&g, start(&g, 0, 1, 40.0), 2).unwrap();
        assert_eq!(r.nodes, vec![1, 2]);
        assert!((r.length - 90.0).abs() < 1e-9);
        // the diagonal is shorter from 0 than round the corner
        let r = plan_route(&g, start(&g, 3, 0, 10.0), 2).unwrap();
        assert_eq!(r.nodes, vec![0, 5, 2]);
        assert!((r.length - (10.0 + 2.0 * 50f64.hypot(25.0))).abs() < 1e-6);
    }

    #[test]
    fn a_goal_behind_is_reached_round_a_loop_never_by_a_u_turn() {
        let g = park();
        // on 0 → 1, 10 m before 1; the goal 0 is 90 m behind, but turning back is not allowed
        let r = plan_route(&g, start(&g, 0, 1, 10.0), 0).unwrap();
        assert_eq!(r.nodes[0], 1);
        assert_ne!(r.nodes[1], 0, "U-turn planned: {:?}", r.nodes);
        assert_eq!(r.nodes, vec![1, 2, 5, 0]);
        assert!((r.length - (10.0 + 50.0 + 2.0 * 50f64.hypot(25.0))).abs() < 1e-6);
        // no route anywhere turns straight back at a node
        for goal in 0..g.nodes.len() {
            for (a, b) in [(0, 1), (1, 0), (2, 3), (5, 2), (3, 0)] {
                if let Ok(r) = plan_route(&g, start(&g, a, b, 1.0), goal) {
                    let mut prev = a;
                    for w in r.nodes.windows(2) {
                        assert_ne!(w[1], prev, "U-turn at {} on {:?}", w[0], r.nodes);
                        prev = w[0];
                    }
                }
            }
        }
    }

    #[test]
    fn a_dead_end_needs_a_u_turn_so_it_is_unreachable_unless_it_is_the_goal() {
        let g = park();
        // facing the dead end 4: any goal but 4 would need turning round
        assert_eq!(
            plan_route(&g, start(&g, 1, 4, 5.0), 0),
            Err(RoadPlanError::Unreachable {
                edge: g.edge_between(1, 4).unwrap(),
                goal: 0
            })
        );
        assert_eq!(
            plan_route(&g, start(&g, 1, 4, 5.0), 4).unwrap().nodes,
            vec![4]
        );
        // and the dead end is a fine goal from elsewhere
        let r = plan_route(&g, start(&g, 3, 0, 1.0), 4).unwrap();
        assert_eq!(r.nodes, vec![0, 1, 4]);
    }

    #[test]
    fn the_park_short_route_goes_round_a_loop_instead_of_turning() {
        // assets/roads: the short route starts at node 37 on Orchard Path facing 344°, away
        // from its goal, node 10; turning round would make it 67.9 m, the route without a
        // U-turn is 190.2 m (the generator's own Dijkstra, `generate_park.py --check`)
        let path = crate::core::source::source_path("assets/roads/park/park.osm");
        let g =
            crate::world::roads::load_roads(&path, &crate::world::roads::RoadOptions::default())
                .unwrap();
        let junctions = (0..g.nodes.len()).filter(|&n| g.degree(n) != 2).count();
        assert!(junctions >= 30, "{junctions} junctions and road ends");
        assert!((0..g.nodes.len()).any(|n| g.degree(n) >= 4));
        let s = g.node_by_source("37").unwrap();
        let goal = g.node_by_source("10").unwrap();
        let off = |&(e, _): &(EdgeId, NodeId)| {
            let d = g.azimuth_from(e, s).to_degrees() - 344.1;
            (d + 180.0).rem_euclid(360.0) - 180.0
        };
        let (ahead, behind) = {
            let mut at: Vec<_> = g.adjacency[s].clone();
            at.sort_by(|x, y| off(x).abs().total_cmp(&off(y).abs()));
            (at[0], at[1])
        };
        let go = |(edge, toward): (EdgeId, NodeId)| {
            plan_route(
                &g,
                RoadStart {
                    edge,
                    toward,
                    remaining: g.edges[edge].length,
                },
                goal,
            )
            .unwrap()
        };
        let forward = go(ahead);
        assert!((forward.length - 190.2).abs() < 0.1, "{}", forward.length);
        assert!((go(behind).length - 67.9).abs() < 0.1);
    }

    #[test]
    fn bad_queries_are_errors() {
        let g = park();
        assert!(matches!(
            plan_route(
                &g,
                RoadStart {
                    edge: 99,
                    toward: 0,
                    remaining: 0.0
                },
                1
            ),
            Err(RoadPlanError::BadStart { .. })
        ));
        let e = g.edge_between(0, 1).unwrap();
        assert!(matches!(
            plan_route(
                &g,
                RoadStart {
                    edge: e,
                    toward: 2,
                    remaining: 0.0
                },
                1
            ),
            Err(RoadPlanError::BadStart { .. })
        ));
        assert_eq!(
            plan_route(&g, start(&g, 0, 1, 0.0), 42),
            Err(RoadPlanError::BadGoal(42))
        );
    }
}
