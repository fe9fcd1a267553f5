//! Road networks for outdoor navigation ([Park thesis §5.1]): OSM XML
//! (nodes and ways with `highway=*`, their `surface` and `width` tags) and GPX 1.1 tracks
//! (`trk/trkseg/trkpt`, also `rte/rtept`), read with `roxmltree`, projected to local metres
//! ([`geo`]) and turned into a [`RoadGraph`].
//!
//! - **Reference point**: the scenario may give one; otherwise it is the centre of the
//!   latitude/longitude bounding box of every road point. Local x points east, y north.
//! - **OSM**: every node of a road way becomes a graph node (shape points too, as the thesis's
//!   graph of points); ways share nodes by id. Ways tagged `area=yes` and highways that are not
//!   roads yet (`proposed`, `construction`, ...) are skipped, as are all other ways and
//!   relations (buildings, woods). Width: the `width` tag in metres (`3.5`, `3.5 m`), else a
//!   default per highway type ([`default_width`]).
//! - **GPX**: each track segment (and route) is a road; points closer than
//!   [`RoadOptions::merge_distance`] become one node, so tracks that pass through the same
//!   junction point are connected. The track's `<type>` names the surface.
//!
//! Malformed input is an error with the file, line and column: not XML, a missing or
//! non-numeric coordinate, a way referring to a node the file lacks, a bad width, no roads.
use crate::core::input::{MAX_DATA_BYTES, read_text_bounded};

pub mod geo;
mod gpx;
pub mod graph;
mod osm;
mod raw;
mod surface;
pub mod surface_raster;

pub use geo::{GeoPoint, LocalProjection, haversine};
pub use graph::{EdgeId, EdgePoint, NodeId, Road, RoadEdge, RoadGraph, RoadNode, RoadStart};
pub use raw::{RoadError, RoadOptions, default_width};
pub use surface::Surface;
pub use surface_raster::{RoadSurface, SurfaceRaster};

use raw::Source;
use std::path::Path;

/// The world's road network, shared by the planner, the road localizers, the camera's road
/// surface and evaluation.
#[derive(bevy_ecs::prelude::Resource, Clone, Debug)]
pub struct RoadMap(pub std::sync::Arc<RoadGraph>);

/// The world's geographic frame: local metres ↔ latitude/longitude, for GPS fixes and roads.
#[derive(bevy_ecs::prelude::Resource, Clone, Copy, Debug, PartialEq)]
pub struct GeoFrame(pub LocalProjection);

/// Reads an OSM XML or GPX file (told apart by the root element).
pub fn load_roads(path: &Path, options: &RoadOptions) -> Result<RoadGraph, RoadError> {
    let text = read_text_bounded(path, MAX_DATA_BYTES).map_err(|source| RoadError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse_roads(&text, path, options)
}

/// A parse error of roxmltree, located: where it happened, or the end of the text for a text
/// that ends too soon (roxmltree gives those no position); said once, in front.
fn xml_error(e: &roxmltree::Error, text: &str, path: &Path) -> RoadError {
    use roxmltree::Error as E;
    let message = e.to_string();
    let (line, column, message) = match e {
        E::UnexpectedEndOfStream | E::UnclosedRootNode | E::NoRootNode => {
            let line = text.matches('\n').count() + 1;
            let last = text.rsplit('\n').next().unwrap_or("");
            let at = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
            (at(line), at(last.chars().count() + 1), message.as_str())
        }
        // limits of the document as a whole: no place to name
        E::DtdDetected
        | E::NodesLimitReached
        | E::AttributesLimitReached
        | E::NamespacesLimitReached => {
            return RoadError::Content {
                path: path.to_path_buf(),
                message: format!("not well-formed XML: {message}"),
            };
        }
        _ => {
            let at = e.pos();
            let suffix = format!(" at {}:{}", at.row, at.col);
            let m = message.strip_suffix(&suffix).unwrap_or(&message);
            (at.row, at.col, m)
        }
    };
    RoadError::At {
        path: path.to_path_buf(),
        line,
        column,
        message: format!("not well-formed XML: {message}"),
    }
}

/// Parses OSM XML or GPX text; `path` only names the source in errors.
pub fn parse_roads(text: &str, path: &Path, options: &RoadOptions) -> Result<RoadGraph, RoadError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| xml_error(&e, text, path))?;
    let src = Source { doc: &doc, path };
    let raw = match doc.root_element().tag_name().name() {
        "osm" => osm::read(&src, options)?,
        "gpx" => gpx::read(&src, options)?,
        other => {
            return Err(src.at(
                doc.root_element(),
                format!("root element <{other}>: expected <osm> (OSM XML) or <gpx> (GPX 1.1)"),
            ));
        }
    };
    raw.into_graph(path, options)
}

#[cfg(test)]
mod tests;
