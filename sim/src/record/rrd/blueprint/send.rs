//! A [`Node`] tree written as Rerun blueprint archetypes (the entity paths the Rerun SDKs use:
//! `viewport`, `container/<id>`, `view/<id>`, its properties and its entities' overrides) into
//! a blueprint store of its own, sent into the recording's file and activated with it.

use super::{Node, Split, SplitKind, ViewSpec};
use crate::record::rrd::stream::RrdStream;
use re_sdk_types::blueprint::archetypes::{
    ContainerBlueprint, EntityBehavior, EyeControls3D, LineGrid3D, PanelBlueprint, PlotLegend,
    ScalarAxis, TimeAxis, TimePanelBlueprint, ViewBlueprint, ViewContents, ViewportBlueprint,
    VisibleTimeRanges,
};
use re_sdk_types::blueprint::components::{
    ContainerKind, Eye3DKind, IncludedContent, LinkAxis, PanelState, PlayState, QueryExpression,
    RootContainer, ViewClass, ViewOrigin,
};
use re_sdk_types::datatypes::{TimeRange, TimeRangeBoundary, VisibleTimeRange};
use rerun::external::re_log_types::{BlueprintActivationCommand, LogMsg};
use rerun::{RecordingStream, RecordingStreamBuilder, RecordingStreamResult};
use uuid::Uuid;

/// Sends `root` as the recording's blueprint, active and default for the application.
pub fn send(rec: &RrdStream, root: &Node) -> anyhow::Result<()> {
    let app = rec
        .application_id()
        .unwrap_or_else(|| rerun::ApplicationId::from("sim"));
    let msgs = blueprint_messages(app, root)
        .map_err(|e| anyhow::anyhow!("building the recording's blueprint: {e:#}"))?;
    let Some(LogMsg::SetStoreInfo(info)) = msgs.first() else {
        anyhow::bail!("building the recording's blueprint: no store info");
    };
    let activation = BlueprintActivationCommand {
        blueprint_id: info.info.store_id.clone(),
        make_active: true,
        make_default: true,
    };
    rec.send_blueprint(msgs, activation);
    Ok(())
}

/// The blueprint store's messages.
fn blueprint_messages(app: rerun::ApplicationId, root: &Node) -> anyhow::Result<Vec<LogMsg>> {
    let (bp, storage) = RecordingStreamBuilder::new(app)
        .recording_id(rerun::external::re_log_types::RecordingId::random())
        .blueprint()
        .memory()?;
    // the viewer reads blueprint data on this timeline
    bp.set_time_sequence("blueprint", 0);
    let root_path = log_node(&bp, root)?;
    let root_id = root_path
        .rsplit('/')
        .next()
        .and_then(|id| Uuid::parse_str(id).ok())
        .unwrap_or_else(Uuid::nil);
    bp.log(
        "viewport",
        &ViewportBlueprint::new()
            .with_root_container(RootContainer(root_id.into()))
            .with_auto_layout(false)
            .with_auto_views(false),
    )?;
    // the views get the window: the blueprint and selection panels start collapsed
    for panel in ["blueprint_panel", "selection_panel"] {
        bp.log(
            panel,
            &PanelBlueprint::new().with_state(PanelState::Collapsed),
        )?;
    }
    bp.log(
        "time_panel",
        &TimePanelBlueprint::new()
            .with_timeline("sim_time")
            .with_play_state(PlayState::Paused),
    )?;
    bp.flush_blocking().map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(storage.take())
}

/// Logs a node (and its children); its blueprint path.
fn log_node(bp: &RecordingStream, node: &Node) -> RecordingStreamResult<String> {
    match node {
        Node::View(v) => log_view(bp, v),
        Node::Split(s) => log_split(bp, s),
    }
}

fn log_split(bp: &RecordingStream, s: &Split) -> RecordingStreamResult<String> {
    let mut children = Vec::with_capacity(s.children.len());
    for c in &s.children {
        children.push(log_node(bp, c)?);
    }
    let kind = match s.kind {
        SplitKind::Horizontal => ContainerKind::Horizontal,
        SplitKind::Vertical => ContainerKind::Vertical,
        SplitKind::Tabs => ContainerKind::Tabs,
    };
    let path = format!("container/{}", Uuid::new_v4());
    let mut arch = ContainerBlueprint::new(kind)
        .with_contents(children.iter().map(|c| IncludedContent(c.as_str().into())));
    if !s.shares.is_empty() {
        let shares = s.shares.iter().copied();
        arch = match s.kind {
            SplitKind::Horizontal => arch.with_col_shares(shares),
            _ => arch.with_row_shares(shares),
        };
    }
    bp.log(path.as_str(), &arch)?;
    Ok(path)
}

fn log_view(bp: &RecordingStream, v: &ViewSpec) -> RecordingStreamResult<String> {
    let path = format!("view/{}", Uuid::new_v4());
    bp.log(
        format!("{path}/ViewContents"),
        &ViewContents::new(
            v.contents
                .iter()
                .map(|q| QueryExpression(q.as_str().into())),
        ),
    )?;
    bp.log(
        path.as_str(),
        &ViewBlueprint::new(ViewClass(v.class.identifier().into()))
            .with_display_name(v.name.as_str())
            .with_space_origin(ViewOrigin::from(v.origin.as_str())),
    )?;
    if let Some([start, end]) = v.x_range {
        let at = |s: f64| TimeRangeBoundary::Absolute(((s.max(0.0) * 1e9).round() as i64).into());
        bp.log(
            format!("{path}/TimeAxis"),
            &TimeAxis::new()
                .with_link(LinkAxis::Independent)
                .with_view_range(TimeRange {
                    start: at(start),
                    end: at(end),
                }),
        )?;
    }
    if let Some([lo, hi]) = v.y_range {
        bp.log(
            format!("{path}/ScalarAxis"),
            &ScalarAxis::new().with_range([lo, hi]),
        )?;
        bp.log(
            format!("{path}/PlotLegend"),
            &PlotLegend::new().with_visible(true),
        )?;
    }
    if v.class == super::ViewClass::Spatial3D {
        bp.log(
            format!("{path}/LineGrid3D"),
            &LineGrid3D::new().with_visible(false),
        )?;
    }
    if let Some([position, target]) = v.eye {
        bp.log(
            format!("{path}/EyeControls3D"),
            &EyeControls3D::new()
                .with_kind(Eye3DKind::Orbital)
                .with_position(position)
                .with_look_target(target)
                .with_eye_up([0.0, 1.0, 0.0]),
        )?;
    }
    for e in &v.hidden {
        bp.log(
            overrides(&path, e),
            &EntityBehavior::new().with_visible(false),
        )?;
    }
    let history = VisibleTimeRange {
        timeline: "sim_time".into(),
        range: TimeRange {
            start: TimeRangeBoundary::Infinite,
            end: TimeRangeBoundary::CursorRelative(0.into()),
        },
    };
    for e in &v.whole_history {
        bp.log(
            overrides(&path, e),
            &VisibleTimeRanges::new([history.clone()]),
        )?;
    }
    Ok(path)
}

/// Where a view's settings for one of its entities go.
fn overrides(view: &str, entity: &str) -> String {
    format!(
        "{view}/ViewContents/overrides/{}/visualizers",
        entity.trim_start_matches('/')
    )
}
