//! Doors: wall segments of the map that open and close at run time (scenario events). Closing a
//! door turns the free cells under it into obstacles through [`StaticWorld::set_cells`], so the
//! ray map, the physics colliders of the touched tiles and everything derived from the world's
//! version (the navigation costmaps) follow; opening restores exactly the cells it took.

use super::static_world::StaticWorld;
use crate::world::grid::Cell;
use crate::world::shapes::Shape;
use bevy_ecs::prelude::Resource;

#[derive(Clone, Debug, PartialEq)]
pub struct Door {
    pub name: String,
    pub from: [f64; 2],
    pub to: [f64; 2],
    pub thickness: f64,
    pub open: bool,
    /// Cells the closed door occupies that are free while it is open.
    cells: Vec<(usize, usize)>,
}

impl Door {
    pub fn new(name: impl Into<String>, from: [f64; 2], to: [f64; 2], thickness: f64) -> Self {
        Door {
            name: name.into(),
            from,
            to,
            thickness,
            open: true,
            cells: Vec::new(),
        }
    }

    fn shape(&self) -> Shape {
        Shape::Wall {
            from: self.from,
            to: self.to,
            thickness: self.thickness,
        }
    }
}

#[derive(Resource, Clone, Debug, Default)]
pub struct Doors {
    pub doors: Vec<Door>,
}

impl Doors {
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.doors.iter().position(|d| d.name == name)
    }

    /// Opens or closes door `i`; returns the cell edits made (empty if it already was so).
    pub fn set(
        &mut self,
        i: usize,
        open: bool,
        world: &mut StaticWorld,
    ) -> Vec<(usize, usize, Cell)> {
        let Some(door) = self.doors.get_mut(i) else {
            return Vec::new();
        };
        if door.open == open {
            return Vec::new();
        }
        door.open = open;
        let edits: Vec<(usize, usize, Cell)> = if open {
            std::mem::take(&mut door.cells)
                .into_iter()
                .map(|(c, r)| (c, r, Cell::Free))
                .collect()
        } else {
            let g = world.grid();
            let shape = door.shape();
            let b = shape.bounds();
            let mut cells = Vec::new();
            for row in 0..g.height {
                let cy = g.origin[1] + (row as f64 + 0.5) * g.resolution;
                if cy < b[1] || cy > b[3] {
                    continue;
                }
                for col in 0..g.width {
                    let cx = g.origin[0] + (col as f64 + 0.5) * g.resolution;
                    if cx >= b[0]
                        && cx <= b[2]
                        && g.get(col, row) == Cell::Free
                        && shape.contains([cx, cy])
                    {
                        cells.push((col, row));
                    }
                }
            }
            door.cells = cells.clone();
            cells
                .into_iter()
                .map(|(c, r)| (c, r, Cell::Occupied))
                .collect()
        };
        world.set_cells(&edits);
        edits
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::OccupancyGrid;

    #[test]
    fn closing_and_opening_restores_the_grid() {
        let mut g = OccupancyGrid::new(100, 60, 0.05, [0.0, 0.0], Cell::Free);
        g.set(10, 10, Cell::Occupied);
        let mut w = StaticWorld::new(g.clone());
        let mut doors = Doors {
            doors: vec![Door::new("d", [0.4, 1.0], [0.8, 1.0], 0.15)],
        };
        let v0 = w.version;
        let closed = doors.set(0, false, &mut w);
        assert!(!closed.is_empty());
        assert!(w.version > v0);
        assert_eq!(w.grid().get(12, 20), Cell::Occupied);
        assert!(w.rays().cast([0.6, 0.5], std::f32::consts::FRAC_PI_2, 5.0) < 0.6);
        assert!(doors.set(0, false, &mut w).is_empty(), "already closed");
        doors.set(0, true, &mut w);
        assert_eq!(w.grid().cells, g.cells);
    }
}
