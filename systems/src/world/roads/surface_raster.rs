//! The road surface as the camera sees it ([Park thesis §5.2]: the robot tells road from its
//! surroundings by colour): the road graph's edges widened to their road's width and rasterized
//! once into a grid of surface classes, which the camera renderer ([`crate::sensors::camera`])
//! looks up per pixel.
//!
//! - Each edge is a capsule (a segment with round ends) of half its road's width, so bends and
//!   junctions join without gaps.
//! - The outer [`VERGE_WIDTH`] of every road is the [`VERGE`] class, a darker worn strip
//!   between surface and grass that makes road edges visible; a road's interior wins over
//!   another road's verge, so verges never cut across junctions.
//! - Outside every road (and outside the grid) is [`GRASS`].
//!
//! Resolution: [`DEFAULT_RESOLUTION`] = 0.05 m. The camera sits 0.5 m above the ground; at the
//! 1.5–4 m the road follower looks at, one pixel spans 0.6–1.5 cm across the road, so a 0.1 m
//! cell would show as a 7–17 px step on every road edge (more than the recognizer's 4 px scan
//! step) and a 0.15 m verge would alias between one and two cells. At 0.05 m the steps are
//! 3–8 px and the verge is three cells. The price is memory: one byte per cell, about 35 MB
//! for the 324 × 274 m park grid (the graph's bounds plus a 15 m margin).

use super::graph::RoadGraph;
use super::surface::Surface;
use crate::core::cache::{CacheKey, Cached, Decoder, Encoder, Malformed, MapCache};

/// Class of the ground off the roads.
pub const GRASS: u8 = 0;
/// Class of the worn strip along every road's edge.
pub const VERGE: u8 = 7;
/// Number of classes ([`GRASS`], the six surfaces, [`VERGE`]).
pub const CLASSES: usize = 8;
/// Width of the verge strip inside each road's edge (m).
pub const VERGE_WIDTH: f64 = 0.15;
/// Default cell size (m); see the module documentation.
pub const DEFAULT_RESOLUTION: f64 = 0.05;
/// Default grass margin around the graph's bounds (m).
pub const DEFAULT_MARGIN: f64 = 15.0;

/// The class of a road surface: `Surface as u8 + 1` (1 asphalt … 6 unknown).
pub const fn surface_class(s: Surface) -> u8 {
    match s {
        Surface::Asphalt => 1,
        Surface::Gravel => 2,
        Surface::Paving => 3,
        Surface::Concrete => 4,
        Surface::Dirt => 5,
        Surface::Unknown => 6,
    }
}

/// Whether a class is a drivable road surface (not grass, not the verge).
pub const fn is_road_class(class: u8) -> bool {
    class >= 1 && class <= 6
}

/// A grid of surface classes over the road network, row-major from the south-west corner.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceRaster {
    /// Cell size (m).
    pub resolution: f64,
    /// World position of the south-west corner of cell (0, 0) (m).
    pub origin: [f64; 2],
    /// Columns (along x, east).
    pub width: usize,
    /// Rows (along y, north).
    pub height: usize,
    /// `width × height` classes; cell (ix, iy) at `iy * width + ix`.
    pub cells: Vec<u8>,
}

impl SurfaceRaster {
    /// A raster without cells: everything is grass.
    pub fn empty() -> Self {
        SurfaceRaster {
            resolution: DEFAULT_RESOLUTION,
            origin: [0.0; 2],
            width: 0,
            height: 0,
            cells: Vec::new(),
        }
    }

    /// Rasterizes `graph` at `resolution` (m) over its bounds grown by `margin` (m).
    pub fn build(graph: &RoadGraph, resolution: f64, margin: f64) -> SurfaceRaster {
        assert!(resolution > 0.0, "resolution must be positive");
        let b = graph.bounds();
        if graph.nodes.is_empty() || !b.iter().all(|v| v.is_finite()) {
            return SurfaceRaster {
                resolution,
                ..SurfaceRaster::empty()
            };
        }
        let widest = graph.roads.iter().map(|r| r.width).fold(0.0, f64::max);
        let m = margin.max(0.5 * widest);
        let origin = [b[0] - m, b[1] - m];
        let width = ((b[2] - b[0] + 2.0 * m) / resolution).ceil() as usize + 1;
        let height = ((b[3] - b[1] + 2.0 * m) / resolution).ceil() as usize + 1;
        let mut r = SurfaceRaster {
            resolution,
            origin,
            width,
            height,
            cells: vec![GRASS; width * height],
        };
        // verges first (full width), then the interiors over them
        for e in &graph.edges {
            let road = &graph.roads[e.road];
            let (a, b) = (graph.nodes[e.a].pos, graph.nodes[e.b].pos);
            r.fill_capsule(a, b, 0.5 * road.width, VERGE);
        }
        for e in &graph.edges {
            let road = &graph.roads[e.road];
            let (a, b) = (graph.nodes[e.a].pos, graph.nodes[e.b].pos);
            let inner = 0.5 * road.width - VERGE_WIDTH;
            if inner > 0.0 {
                r.fill_capsule(a, b, inner, surface_class(road.surface));
            }
        }
        r
    }

    /// [`SurfaceRaster::build`] through `cache`.
    pub fn build_cached(
        graph: &RoadGraph,
        resolution: f64,
        margin: f64,
        cache: &MapCache,
    ) -> SurfaceRaster {
        // what `build` reads: node positions, edges, road widths and surfaces
        let mut key = CacheKey::new::<SurfaceRaster>()
            .f64(resolution)
            .f64(margin)
            .u64(graph.nodes.len() as u64);
        for n in &graph.nodes {
            key = key.f64(n.pos[0]).f64(n.pos[1]);
        }
        key = key.u64(graph.roads.len() as u64);
        for r in &graph.roads {
            key = key.f64(r.width).u64(surface_class(r.surface).into());
        }
        key = key.u64(graph.edges.len() as u64);
        for e in &graph.edges {
            key = key.u64(e.a as u64).u64(e.b as u64).u64(e.road as u64);
        }
        cache.get_or_build(&key, || SurfaceRaster::build(graph, resolution, margin))
    }

    /// Sets every cell whose centre is within `radius` of segment `a`–`b` to `class`.
    fn fill_capsule(&mut self, a: [f64; 2], b: [f64; 2], radius: f64, class: u8) {
        let res = self.resolution;
        let lo = [a[0].min(b[0]) - radius, a[1].min(b[1]) - radius];
        let hi = [a[0].max(b[0]) + radius, a[1].max(b[1]) + radius];
        let cell =
            |v: f64, o: f64, n: usize| ((v - o) / res).floor().clamp(0.0, n as f64 - 1.0) as usize;
        let (x0, x1) = (
            cell(lo[0], self.origin[0], self.width),
            cell(hi[0], self.origin[0], self.width),
        );
        let (y0, y1) = (
            cell(lo[1], self.origin[1], self.height),
            cell(hi[1], self.origin[1], self.height),
        );
        let d = [b[0] - a[0], b[1] - a[1]];
        let l2 = d[0] * d[0] + d[1] * d[1];
        let r2 = radius * radius;
        for iy in y0..=y1 {
            let py = self.origin[1] + (iy as f64 + 0.5) * res;
            let row = &mut self.cells[iy * self.width..(iy + 1) * self.width];
            for (ix, c) in row.iter_mut().enumerate().take(x1 + 1).skip(x0) {
                let px = self.origin[0] + (ix as f64 + 0.5) * res;
                let q = [px - a[0], py - a[1]];
                let t = if l2 > 0.0 {
                    ((q[0] * d[0] + q[1] * d[1]) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (ex, ey) = (q[0] - t * d[0], q[1] - t * d[1]);
                if ex * ex + ey * ey <= r2 {
                    *c = class;
                }
            }
        }
    }

    /// The class at world point (x, y): [`GRASS`] outside the grid.
    #[inline]
    pub fn class_at(&self, x: f64, y: f64) -> u8 {
        let fx = (x - self.origin[0]) / self.resolution;
        let fy = (y - self.origin[1]) / self.resolution;
        self.class_at_cell(fx.floor() as i64, fy.floor() as i64)
    }

    /// The class of cell (ix, iy): [`GRASS`] outside the grid.
    #[inline]
    pub fn class_at_cell(&self, ix: i64, iy: i64) -> u8 {
        if ix < 0 || iy < 0 || ix >= self.width as i64 || iy >= self.height as i64 {
            GRASS
        } else {
            self.cells[iy as usize * self.width + ix as usize]
        }
    }

    /// Memory held by the cells (bytes).
    pub fn bytes(&self) -> usize {
        self.cells.len()
    }
}

/// Every field; the cells as runs (mostly grass).
impl Cached for SurfaceRaster {
    const KIND: &'static str = "road_surface";
    const FORMAT: u32 = 1;

    fn encode(&self, out: &mut Encoder) {
        out.f64(self.resolution);
        out.f64(self.origin[0]);
        out.f64(self.origin[1]);
        out.usize(self.width);
        out.usize(self.height);
        out.byte_runs(&self.cells);
    }

    fn decode(input: &mut Decoder<'_>) -> Result<Self, Malformed> {
        let r = SurfaceRaster {
            resolution: input.f64()?,
            origin: [input.f64()?, input.f64()?],
            width: input.usize()?,
            height: input.usize()?,
            cells: input.byte_runs()?,
        };
        if Some(r.cells.len()) != r.width.checked_mul(r.height) {
            return Err(Malformed("road surface: cell count"));
        }
        Ok(r)
    }
}

/// The world's rasterized road surface, shared by every camera.
#[derive(bevy_ecs::prelude::Resource, Clone, Debug)]
pub struct RoadSurface(pub std::sync::Arc<SurfaceRaster>);

impl RoadSurface {
    /// Rasterizes `graph` at the default resolution and margin.
    pub fn from_graph(graph: &RoadGraph) -> Self {
        RoadSurface(std::sync::Arc::new(SurfaceRaster::build(
            graph,
            DEFAULT_RESOLUTION,
            DEFAULT_MARGIN,
        )))
    }
}

/// The park's road graph and its raster at the default resolution, built once per test binary.
#[cfg(test)]
pub(crate) fn park_fixture() -> &'static (RoadGraph, std::sync::Arc<SurfaceRaster>) {
    static PARK: std::sync::OnceLock<(RoadGraph, std::sync::Arc<SurfaceRaster>)> =
        std::sync::OnceLock::new();
    PARK.get_or_init(|| {
        let path = crate::core::source::source_path("assets/roads/park/park.osm");
        let g = super::load_roads(&path, &super::RoadOptions::default()).unwrap();
        let r = SurfaceRaster::build(&g, DEFAULT_RESOLUTION, DEFAULT_MARGIN);
        (g, std::sync::Arc::new(r))
    })
}

/// A pose in the park: `along` metres from OSM node `from` towards node `to`, `left` metres
/// left of the line, heading from `from` to `to`.
#[cfg(test)]
pub(crate) fn park_pose(from: &str, to: &str, along: f64, left: f64) -> crate::core::Pose2 {
    let g = &park_fixture().0;
    let a = g.nodes[g.node_by_source(from).unwrap()].pos;
    let b = g.nodes[g.node_by_source(to).unwrap()].pos;
    let yaw = (b[1] - a[1]).atan2(b[0] - a[0]);
    let (s, c) = yaw.sin_cos();
    crate::core::Pose2::new(
        a[0] + along * c - left * s,
        a[1] + along * s + left * c,
        yaw,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn park() -> RoadGraph {
        park_fixture().0.clone()
    }

    #[test]
    fn roads_have_their_surface_width_and_verge() {
        let g = park();
        let r = &park_fixture().1;
        let b = g.bounds();
        assert!(r.origin[0] <= b[0] - 15.0 && r.origin[1] <= b[1] - 15.0);
        assert!(r.origin[0] + r.width as f64 * 0.05 >= b[2] + 15.0);
        // every edge's midpoint carries its road's surface; a point just inside the edge of the
        // road is verge, one just outside is grass (unless another road is there)
        let mut checked = 0;
        for (i, e) in g.edges.iter().enumerate() {
            let road = &g.roads[e.road];
            let mid = g.point_on(i, 0.5 * e.length);
            let (pa, pb) = (g.nodes[e.a].pos, g.nodes[e.b].pos);
            let n = [-(pb[1] - pa[1]) / e.length, (pb[0] - pa[0]) / e.length];
            let at = |off: f64| r.class_at(mid[0] + off * n[0], mid[1] + off * n[1]);
            let half = 0.5 * road.width;
            if g.surface_at([mid[0] + (half + 0.3) * n[0], mid[1] + (half + 0.3) * n[1]])
                .is_some()
                || g.surface_at([mid[0] - (half + 0.3) * n[0], mid[1] - (half + 0.3) * n[1]])
                    .is_some()
            {
                continue; // another road runs alongside
            }
            assert_eq!(at(0.0), surface_class(road.surface), "edge {i}");
            assert_eq!(at(half - 0.3), surface_class(road.surface), "edge {i}");
            assert_eq!(at(half - 0.07), VERGE, "edge {i}");
            assert_eq!(at(-(half - 0.07)), VERGE, "edge {i}");
            assert_eq!(at(half + 0.1), GRASS, "edge {i}");
            assert_eq!(at(-(half + 0.1)), GRASS, "edge {i}");
            checked += 1;
        }
        assert!(checked > 100, "{checked}");
        // far outside the grid is grass
        assert_eq!(r.class_at(1e4, -1e4), GRASS);
        assert_eq!(SurfaceRaster::empty().class_at(0.0, 0.0), GRASS);
        // about 35 MB for the park at 5 cm
        assert!(r.bytes() < 40_000_000, "{}", r.bytes());
    }

    #[test]
    fn junctions_have_no_verge_across_the_road() {
        let g = park();
        let r = &park_fixture().1;
        // every node of degree ≥ 3 is road surface, not verge, in a 0.5 m disc around it
        for (n, node) in g.nodes.iter().enumerate() {
            if g.degree(n) < 3 {
                continue;
            }
            for k in 0..16 {
                let a = k as f64 * std::f64::consts::TAU / 16.0;
                let c = r.class_at(node.pos[0] + 0.5 * a.cos(), node.pos[1] + 0.5 * a.sin());
                assert!(is_road_class(c), "node {n}: class {c}");
            }
        }
    }
}
