//! Vector geometry from scenario files (walls, boxes, discs), rasterised into the occupancy grid so
//! lasers and physics see exactly the same world. A cell is occupied when its centre lies inside a
//! shape.

use super::grid::{Cell, OccupancyGrid};

#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A wall: a thick segment.
    Wall {
        from: [f64; 2],
        to: [f64; 2],
        thickness: f64,
    },
    /// A box: centre, full size (x, y) and yaw.
    Box {
        center: [f64; 2],
        size: [f64; 2],
        yaw: f64,
    },
    /// A disc (pillar).
    Disc { center: [f64; 2], radius: f64 },
}

impl Shape {
    /// Axis-aligned bounds (min x, min y, max x, max y).
    pub fn bounds(&self) -> [f64; 4] {
        match self {
            Shape::Wall {
                from,
                to,
                thickness,
            } => {
                let h = thickness / 2.0;
                [
                    from[0].min(to[0]) - h,
                    from[1].min(to[1]) - h,
                    from[0].max(to[0]) + h,
                    from[1].max(to[1]) + h,
                ]
            }
            Shape::Box { center, size, yaw } => {
                let (s, c) = yaw.sin_cos();
                let ex = (c * size[0]).abs() / 2.0 + (s * size[1]).abs() / 2.0;
                let ey = (s * size[0]).abs() / 2.0 + (c * size[1]).abs() / 2.0;
                [
                    center[0] - ex,
                    center[1] - ey,
                    center[0] + ex,
                    center[1] + ey,
                ]
            }
            Shape::Disc { center, radius } => [
                center[0] - radius,
                center[1] - radius,
                center[0] + radius,
                center[1] + radius,
            ],
        }
    }

    pub fn contains(&self, p: [f64; 2]) -> bool {
        match self {
            Shape::Wall {
                from,
                to,
                thickness,
            } => {
                // a wall is a rectangle around the segment (square ends, like drawn walls)
                let d = [to[0] - from[0], to[1] - from[1]];
                let len = d[0].hypot(d[1]);
                let h = thickness / 2.0;
                if len < 1e-12 {
                    return (p[0] - from[0]).abs() <= h && (p[1] - from[1]).abs() <= h;
                }
                let u = [d[0] / len, d[1] / len];
                let v = [p[0] - from[0], p[1] - from[1]];
                let along = v[0] * u[0] + v[1] * u[1];
                let across = -v[0] * u[1] + v[1] * u[0];
                along >= -h && along <= len + h && across.abs() <= h
            }
            Shape::Box { center, size, yaw } => {
                let (s, c) = yaw.sin_cos();
                let v = [p[0] - center[0], p[1] - center[1]];
                let lx = c * v[0] + s * v[1];
                let ly = -s * v[0] + c * v[1];
                lx.abs() <= size[0] / 2.0 && ly.abs() <= size[1] / 2.0
            }
            Shape::Disc { center, radius } => (p[0] - center[0]).hypot(p[1] - center[1]) <= *radius,
        }
    }
}

/// Marks every cell whose centre lies inside `shape` as occupied.
pub fn rasterize(grid: &mut OccupancyGrid, shape: &Shape) {
    let [x0, y0, x1, y1] = shape.bounds();
    let res = grid.resolution;
    let c0 = ((x0 - grid.origin[0]) / res - 0.5).floor().max(0.0) as usize;
    let r0 = ((y0 - grid.origin[1]) / res - 0.5).floor().max(0.0) as usize;
    let c1 = ((x1 - grid.origin[0]) / res).ceil().max(0.0) as usize;
    let r1 = ((y1 - grid.origin[1]) / res).ceil().max(0.0) as usize;
    for row in r0..r1.min(grid.height) {
        for col in c0..c1.min(grid.width) {
            if shape.contains(grid.cell_center(col, row)) {
                grid.set(col, row, Cell::Occupied);
            }
        }
    }
}

/// The smallest grid at `resolution` covering all shapes plus `margin`, every cell free.
pub fn grid_for_shapes(shapes: &[Shape], resolution: f64, margin: f64) -> Option<OccupancyGrid> {
    let b = shapes_bounds(shapes)?;
    let origin = [b[0] - margin, b[1] - margin];
    let w = ((b[2] + margin - origin[0]) / resolution).ceil() as usize;
    let h = ((b[3] + margin - origin[1]) / resolution).ceil() as usize;
    Some(OccupancyGrid::new(
        w.max(1),
        h.max(1),
        resolution,
        origin,
        Cell::Free,
    ))
}

/// `[min_x, min_y, max_x, max_y]` around every shape; `None` without shapes.
pub fn shapes_bounds(shapes: &[Shape]) -> Option<[f64; 4]> {
    let mut b = [f64::MAX, f64::MAX, f64::MIN, f64::MIN];
    for s in shapes {
        let sb = s.bounds();
        b = [
            b[0].min(sb[0]),
            b[1].min(sb[1]),
            b[2].max(sb[2]),
            b[3].max(sb[3]),
        ];
    }
    (!shapes.is_empty()).then_some(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wall_box_and_disc_rasterize_where_expected() {
        let mut g = OccupancyGrid::new(100, 100, 0.1, [0.0, 0.0], Cell::Free);
        rasterize(
            &mut g,
            &Shape::Wall {
                from: [1.0, 1.0],
                to: [5.0, 1.0],
                thickness: 0.2,
            },
        );
        assert!(g.is_obstacle(30, 10) && g.is_obstacle(30, 9));
        assert!(!g.is_obstacle(30, 11) && !g.is_obstacle(30, 8));
        rasterize(
            &mut g,
            &Shape::Box {
                center: [7.0, 7.0],
                size: [1.0, 0.4],
                yaw: std::f64::consts::FRAC_PI_2,
            },
        );
        // rotated 90°: 0.4 wide in x, 1.0 tall in y
        assert!(g.is_obstacle(70, 74) && !g.is_obstacle(73, 70));
        rasterize(
            &mut g,
            &Shape::Disc {
                center: [3.0, 6.0],
                radius: 0.5,
            },
        );
        assert!(g.is_obstacle(30, 60) && g.is_obstacle(34, 60) && !g.is_obstacle(36, 60));
    }

    #[test]
    fn grid_covers_shapes() {
        let shapes = [Shape::Wall {
            from: [-2.0, 0.0],
            to: [2.0, 3.0],
            thickness: 0.1,
        }];
        let g = grid_for_shapes(&shapes, 0.05, 1.0).unwrap();
        let b = g.bounds();
        assert!(b[0] <= -3.05 && b[1] <= -1.05 && b[2] >= 3.05 && b[3] >= 4.05);
    }
}
