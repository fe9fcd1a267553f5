//! The surface of a road: the classes of OSM `surface=*` and GPX `<type>` values that the
//! graph's edges carry and the camera's raster paints. A leaf of its own, read by the readers,
//! the graph and the raster.

/// The surface of a road, from OSM `surface=*` or a GPX track's `<type>`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Surface {
    Asphalt,
    /// gravel, fine_gravel, compacted, pebblestone
    Gravel,
    /// paving_stones, sett, cobblestone, concrete:plates, bricks
    Paving,
    Concrete,
    /// dirt, earth, ground, mud, sand, grass, unpaved
    Dirt,
    /// No tag, or a value none of the above covers.
    Unknown,
}

impl Surface {
    pub fn from_tag(v: &str) -> Surface {
        match v.trim().to_ascii_lowercase().as_str() {
            "asphalt" | "paved" | "chipseal" => Surface::Asphalt,
            "gravel" | "fine_gravel" | "compacted" | "pebblestone" => Surface::Gravel,
            "paving_stones" | "sett" | "cobblestone" | "unhewn_cobblestone" | "concrete:plates"
            | "bricks" => Surface::Paving,
            "concrete" | "concrete:lanes" => Surface::Concrete,
            "dirt" | "earth" | "ground" | "mud" | "sand" | "grass" | "unpaved" => Surface::Dirt,
            _ => Surface::Unknown,
        }
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Surface::Asphalt => "asphalt",
            Surface::Gravel => "gravel",
            Surface::Paving => "paving",
            Surface::Concrete => "concrete",
            Surface::Dirt => "dirt",
            Surface::Unknown => "unknown",
        }
    }
}
