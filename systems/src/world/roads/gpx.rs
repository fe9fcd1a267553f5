//! GPX 1.1 (and 1.0): every track segment `trk/trkseg/trkpt` and every route `rte/rtept` is a
//! road; the track's `<name>` names it and its `<type>` gives the surface. The thesis reduced
//! the OpenStreetMap export of its park to such tracks ([Park thesis §5.1]).

use super::graph::Road;
use super::raw::{RawRoads, RoadError, RoadOptions, Source, default_width};
use super::surface::Surface;

pub(super) fn read(src: &Source, options: &RoadOptions) -> Result<RawRoads, RoadError> {
    let root = src.doc.root_element();
    let width = options.width.unwrap_or_else(|| default_width("gpx"));
    let child_text = |n: roxmltree::Node, tag: &str| {
        n.children()
            .find(|c| c.has_tag_name(tag))
            .and_then(|c| c.text())
            .map(|t| t.trim().to_string())
    };
    let mut points = Vec::new();
    let mut roads = Vec::new();
    let mut push =
        |name: String, surface: Surface, pts: Vec<roxmltree::Node>| -> Result<(), RoadError> {
            let mut nodes = Vec::with_capacity(pts.len());
            for (k, p) in pts.into_iter().enumerate() {
                let g = src.geo(p)?;
                nodes.push(points.len());
                points.push((g, format!("{name} point {k}")));
            }
            // a single point is no road
            if nodes.len() >= 2 {
                roads.push(Road {
                    name,
                    kind: "gpx".to_string(),
                    surface,
                    width,
                    nodes,
                });
            }
            Ok(())
        };
    for (t, trk) in by_tag(root, "trk").into_iter().enumerate() {
        let name = child_text(trk, "name").unwrap_or_else(|| format!("track {t}"));
        let surface = child_text(trk, "type").map_or(Surface::Unknown, |v| Surface::from_tag(&v));
        let segs = by_tag(trk, "trkseg");
        let many = segs.len() > 1;
        for (s, seg) in segs.into_iter().enumerate() {
            let seg_name = if many {
                format!("{name} segment {s}")
            } else {
                name.clone()
            };
            push(seg_name, surface, by_tag(seg, "trkpt"))?;
        }
    }
    for (r, rte) in by_tag(root, "rte").into_iter().enumerate() {
        let name = child_text(rte, "name").unwrap_or_else(|| format!("route {r}"));
        let surface = child_text(rte, "type").map_or(Surface::Unknown, |v| Surface::from_tag(&v));
        push(name, surface, by_tag(rte, "rtept"))?;
    }
    Ok(RawRoads {
        points,
        roads,
        merge: true,
        what: "no track segment or route with at least two points",
    })
}

/// The children of `n` named `tag`.
fn by_tag<'a, 'i>(n: roxmltree::Node<'a, 'i>, tag: &str) -> Vec<roxmltree::Node<'a, 'i>> {
    n.children().filter(|c| c.has_tag_name(tag)).collect()
}
