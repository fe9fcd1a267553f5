//! The recording's default layout: a Rerun blueprint sent inside every .rrd, so the viewer opens
//! without any click on a layout made for the run instead of one it invents.
//!
//! [`default_layout`] decides it as plain data from the entities the run logged (unit-tested
//! without Rerun); [`send`] writes it as blueprint archetypes into the recording's file:
//! - left, the **map**: a 3-D view of the floor plane seen from straight above, framing the
//!   map. The occupancy grid (`GridMap`) is drawn only by 3-D views, so the map is a 3-D view
//!   whose eye looks down rather than a 2-D view. One localizer per robot is shown (the
//!   scenario's `record.map_localizer` where the robot has it, else its first); the others, the
//!   odometry and the costmap are in the view but hidden, a click away in the blueprint panel.
//!   Paths (`…/path`) are sent as new segments only and drawn from the start of the run to the
//!   time cursor;
//! - right, one **time-series** view per metric family (position error, heading error,
//!   odometry drift, distance left to the goal), every robot's series in it, the y axis from
//!   0 to a bound that the bulk of
//!   the run's values fit (a lost localizer's 50 m does not flatten the others' centimetres);
//!   the camera images of outdoor robots; a **text-log** view of the run's events.
//!
//! The time panel is on `sim_time`, paused: Rerun 0.36 has no blueprint setting for the
//! cursor's position, so the viewer puts it where it puts it for any file.

mod send;
#[cfg(test)]
mod tests;

pub use send::send;

/// A blueprint: containers and views, the root first.
#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    View(ViewSpec),
    Split(Split),
}

/// How a container lays out its children.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitKind {
    Horizontal,
    Vertical,
    Tabs,
}

/// A container.
#[derive(Clone, Debug, PartialEq)]
pub struct Split {
    pub kind: SplitKind,
    /// The children's shares of the container (empty: equal).
    pub shares: Vec<f32>,
    pub children: Vec<Node>,
}

/// Rerun's view classes used here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewClass {
    Spatial3D,
    Spatial2D,
    TimeSeries,
    TextLog,
}

impl ViewClass {
    /// Rerun's class identifier.
    pub fn identifier(self) -> &'static str {
        match self {
            ViewClass::Spatial3D => "3D",
            ViewClass::Spatial2D => "2D",
            ViewClass::TimeSeries => "TimeSeries",
            ViewClass::TextLog => "TextLog",
        }
    }
}

/// One view.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSpec {
    pub class: ViewClass,
    pub name: String,
    pub origin: String,
    /// Rerun query expressions (`/a/**`, `- /a/b`).
    pub contents: Vec<String>,
    /// Entities in the view but not drawn (switchable in the viewer).
    pub hidden: Vec<String>,
    /// Entities drawn from the start of the run to the time cursor (paths sent as segments).
    pub whole_history: Vec<String>,
    /// The y axis of a time series.
    pub y_range: Option<[f64; 2]>,
    /// The time axis of a time series: the run's start and end (s).
    pub x_range: Option<[f64; 2]>,
    /// The eye of a 3-D view: position and look target.
    pub eye: Option<[[f32; 3]; 2]>,
}

impl ViewSpec {
    fn new(class: ViewClass, name: &str, origin: &str, contents: Vec<String>) -> Self {
        ViewSpec {
            class,
            name: name.to_string(),
            origin: origin.to_string(),
            contents,
            hidden: Vec::new(),
            whole_history: Vec::new(),
            y_range: None,
            x_range: None,
            eye: None,
        }
    }
}

impl Node {
    /// Every view, depth first.
    pub fn views(&self) -> Vec<&ViewSpec> {
        match self {
            Node::View(v) => vec![v],
            Node::Split(s) => s.children.iter().flat_map(Node::views).collect(),
        }
    }
}

/// What the layout is made from.
#[derive(Clone, Debug, Default)]
pub struct Inputs<'a> {
    /// The entities logged (no leading `/`), robots' in robot order.
    pub paths: &'a [String],
    /// The localizer the map shows, where a robot has it (`record.map_localizer`).
    pub map_localizer: Option<&'a str>,
    /// The map's extent: min x, min y, max x, max y (m).
    pub bounds: Option<[f64; 4]>,
    /// Upper end of the position-error axis (m), and of the heading-error axis (rad).
    pub position_axis: f64,
    pub heading_axis: f64,
    /// Upper end of the odometry-drift axis (m).
    pub drift_axis: f64,
    /// Upper end of the distance-to-goal axis (m).
    pub goal_axis: f64,
    /// The run's time span (s): every plot shows all of it.
    pub time_span: Option<[f64; 2]>,
}

/// A robot as its entities show it.
#[derive(Debug, Default)]
struct RobotEntities {
    name: String,
    /// Localizers with an estimate, in the order logged.
    localizers: Vec<String>,
    camera: bool,
    errors: bool,
    heading_errors: bool,
    drift: bool,
    goal_distance: bool,
    paths: Vec<String>,
    odometry: bool,
}

/// The robots, in the order of their first entity.
fn robots(paths: &[String]) -> Vec<RobotEntities> {
    let mut out: Vec<RobotEntities> = Vec::new();
    for p in paths {
        let parts: Vec<&str> = p.split('/').collect();
        if parts.len() < 3 || parts[0] != "robots" {
            continue;
        }
        let k = match out.iter().position(|r| r.name == parts[1]) {
            Some(k) => k,
            None => {
                out.push(RobotEntities {
                    name: parts[1].to_string(),
                    ..Default::default()
                });
                out.len() - 1
            }
        };
        let r = &mut out[k];
        match parts[2..] {
            ["estimate", l] if !r.localizers.iter().any(|x| x == l) => {
                r.localizers.push(l.to_string())
            }
            ["camera"] => r.camera = true,
            ["error", ..] => r.errors = true,
            ["heading_error", ..] => r.heading_errors = true,
            ["odometry", "drift"] => r.drift = true,
            ["goal_distance"] => r.goal_distance = true,
            ["odometry", ..] => r.odometry = true,
            _ => {}
        }
        if parts.last() == Some(&"path") && parts[2] != "path" {
            r.paths.push(p.clone());
        }
    }
    out
}

/// The eye above the middle of `b` from which the 3-D view's default field of view (about
/// 40° vertically) sees all of it in a view about 1.4 times wider than high (the map's share
/// of a 16:10 window).
fn eye_over(b: [f64; 4]) -> [[f32; 3]; 2] {
    let (cx, cy) = (0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3]));
    let (w, h) = ((b[2] - b[0]).max(1.0), (b[3] - b[1]).max(1.0));
    let height = 1.05 * w.max(1.4 * h);
    [
        [cx as f32, cy as f32, height as f32],
        [cx as f32, cy as f32, 0.0],
    ]
}

/// A time-series view of one family of series, one query per robot that has it.
fn series_view(name: &str, queries: Vec<String>, top: f64, span: Option<[f64; 2]>) -> Option<Node> {
    if queries.is_empty() {
        return None;
    }
    let mut v = ViewSpec::new(ViewClass::TimeSeries, name, "/", queries);
    v.y_range = Some([0.0, top]);
    v.x_range = span;
    Some(Node::View(v))
}

/// The default layout of a run that logged `inputs.paths`.
pub fn default_layout(inputs: &Inputs) -> Node {
    let robots = robots(inputs.paths);
    let has = |p: &str| inputs.paths.iter().any(|x| x == p);

    let mut map = ViewSpec::new(ViewClass::Spatial3D, "Map", "/", vec!["/**".into()]);
    for r in &robots {
        if r.camera {
            map.contents.push(format!("- /robots/{}/camera", r.name));
        }
        let shown = inputs
            .map_localizer
            .filter(|l| r.localizers.iter().any(|x| x == l))
            .or(r.localizers.first().map(String::as_str));
        for l in r.localizers.iter().filter(|l| Some(l.as_str()) != shown) {
            map.hidden.push(format!("robots/{}/estimate/{l}", r.name));
            let particles = format!("robots/{}/particles/{l}", r.name);
            if has(&particles) {
                map.hidden.push(particles);
            }
        }
        if r.odometry {
            map.hidden.push(format!("robots/{}/odometry", r.name));
        }
        map.whole_history.extend(r.paths.iter().cloned());
    }
    if has("world/costmap") {
        map.hidden.push("world/costmap".into());
    }
    map.eye = inputs.bounds.map(eye_over);

    let family = |f: &dyn Fn(&RobotEntities) -> bool, leaf: &str| -> Vec<String> {
        robots
            .iter()
            .filter(|r| f(r))
            .map(|r| format!("/robots/{}/{leaf}", r.name))
            .collect()
    };
    let mut right: Vec<Node> = Vec::new();
    let cameras: Vec<Node> = robots
        .iter()
        .filter(|r| r.camera)
        .map(|r| {
            let origin = format!("/robots/{}/camera", r.name);
            Node::View(ViewSpec::new(
                ViewClass::Spatial2D,
                &format!("{} camera", r.name),
                &origin,
                vec![format!("{origin}/**")],
            ))
        })
        .collect();
    match cameras.len() {
        0 => {}
        1 => right.extend(cameras),
        _ => right.push(Node::Split(Split {
            kind: SplitKind::Tabs,
            shares: Vec::new(),
            children: cameras,
        })),
    }
    right.extend(series_view(
        "Position error (m)",
        family(&|r| r.errors, "error/**"),
        inputs.position_axis,
        inputs.time_span,
    ));
    right.extend(series_view(
        "Heading error (rad)",
        family(&|r| r.heading_errors, "heading_error/**"),
        inputs.heading_axis,
        inputs.time_span,
    ));
    right.extend(series_view(
        "Odometry drift (m)",
        family(&|r| r.drift, "odometry/drift"),
        inputs.drift_axis,
        inputs.time_span,
    ));
    right.extend(series_view(
        "Distance to goal (m)",
        family(&|r| r.goal_distance, "goal_distance"),
        inputs.goal_axis,
        inputs.time_span,
    ));
    right.push(Node::View(ViewSpec::new(
        ViewClass::TextLog,
        "Events",
        "/",
        vec!["/**".into()],
    )));
    let column = Node::Split(Split {
        kind: SplitKind::Vertical,
        shares: Vec::new(),
        children: right,
    });
    Node::Split(Split {
        kind: SplitKind::Horizontal,
        shares: vec![3.0, 2.0],
        children: vec![Node::View(map), column],
    })
}
