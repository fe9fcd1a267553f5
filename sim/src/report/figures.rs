//! The report's figures as SVG documents (plotters' SVG backend: text is left to the browser,
//! so no font file is needed): the map with every robot's true and estimated paths, position
//! error over time, the task timeline and box plots. Colours are the recording's
//! ([`crate::record::colours`]).

use super::data::{MapCells, Outcome, RoadLine, RobotTrace};
use crate::record::axis_scale::AxisScale;
use crate::record::colours;
use plotters::prelude::*;

/// Width of every figure (px).
pub const WIDTH: u32 = 960;

type Fig = anyhow::Result<String>;

fn colour(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

fn err(e: impl std::fmt::Debug) -> anyhow::Error {
    anyhow::anyhow!("drawing a figure: {e:?}")
}

/// The extent of the map, the roads and every path: min x, min y, max x, max y, with a margin.
fn extent(map: Option<&MapCells>, roads: &[RoadLine], robots: &[RobotTrace]) -> Option<[f64; 4]> {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    // a report.json edited by hand may hold anything: non-finite points are left out
    let mut add = |x: f64, y: f64| {
        if x.is_finite() && y.is_finite() {
            b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
        }
    };
    if let Some(m) = map {
        add(m.origin[0], m.origin[1]);
        add(
            m.origin[0] + m.size[0] as f64 * m.resolution,
            m.origin[1] + m.size[1] as f64 * m.resolution,
        );
    }
    for p in roads.iter().flat_map(|r| &r.points) {
        add(p[0] as f64, p[1] as f64);
    }
    for r in robots {
        let strips = r
            .truth
            .iter()
            .chain(r.localizers.iter().flat_map(|l| &l.path));
        for p in strips.flatten() {
            add(p[0] as f64, p[1] as f64);
        }
    }
    let pad = 0.02 * (b[2] - b[0]).max(b[3] - b[1]).max(1.0);
    (b[0] <= b[2]).then(|| [b[0] - pad, b[1] - pad, b[2] + pad, b[3] + pad])
}

/// The map (occupied cells grey, roads light brown at their width), each robot's true path in
/// its colour and each localizer's estimated path in a thinner shade of it, metres on both
/// axes at the same scale.
pub fn map_figure(map: Option<&MapCells>, roads: &[RoadLine], robots: &[RobotTrace]) -> Fig {
    let Some(b) = extent(map, roads, robots) else {
        return Ok(String::new());
    };
    let (label_y, label_x, margin) = (50u32, 40u32, 10u32);
    let plot_w = (WIDTH - label_y - 2 * margin) as f64;
    let plot_h = plot_w * (b[3] - b[1]) / (b[2] - b[0]);
    let height = (plot_h.clamp(120.0, 1400.0) as u32) + label_x + 2 * margin + 10;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .margin(margin)
            .x_label_area_size(label_x)
            .y_label_area_size(label_y)
            .build_cartesian_2d(b[0]..b[2], b[1]..b[3])
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x (m)")
            .y_desc("y (m)")
            .draw()
            .map_err(err)?;
        if let Some(m) = map {
            let grey = RGBColor(110, 110, 110).filled();
            let cell = m.resolution;
            chart
                .draw_series(m.occupied.iter().map(|&[row, x0, x1]| {
                    let y = m.origin[1] + row as f64 * cell;
                    Rectangle::new(
                        [
                            (m.origin[0] + x0 as f64 * cell, y),
                            (m.origin[0] + x1 as f64 * cell, y + cell),
                        ],
                        grey,
                    )
                }))
                .map_err(err)?;
        }
        // a road as wide as it is: its width in pixels at the plot's scale
        let px_per_m = plot_w / (b[2] - b[0]);
        for road in roads {
            let w = ((road.width * px_per_m).round() as u32).max(1);
            chart
                .draw_series(LineSeries::new(
                    road.points.iter().map(|p| (p[0] as f64, p[1] as f64)),
                    RGBColor(222, 205, 170).stroke_width(w),
                ))
                .map_err(err)?;
        }
        for (i, r) in robots.iter().enumerate() {
            let c = colour(colours::robot(i as u32));
            for (k, strip) in r.truth.iter().enumerate() {
                let series = chart
                    .draw_series(LineSeries::new(
                        strip.iter().map(|p| (p[0] as f64, p[1] as f64)),
                        c.stroke_width(2),
                    ))
                    .map_err(err)?;
                if k == 0 {
                    series
                        .label(format!("{} truth", r.name))
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2))
                        });
                }
            }
            for (k, l) in r.localizers.iter().enumerate() {
                let c = colour(colours::localizer(i as u32, k));
                for (n, strip) in l.path.iter().enumerate() {
                    let series = chart
                        .draw_series(LineSeries::new(
                            strip.iter().map(|p| (p[0] as f64, p[1] as f64)),
                            c.stroke_width(1),
                        ))
                        .map_err(err)?;
                    if n == 0 {
                        series
                            .label(format!("{} {}", r.name, l.name))
                            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c));
                    }
                }
            }
        }
        if robots
            .iter()
            .any(|r| !r.truth.is_empty() || !r.localizers.is_empty())
        {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()
                .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// Position error over time of every localizer of robot `index`, the y axis from 0 to a
/// quarter above what three quarters of the errors stay under (as the recording's plots).
pub fn error_figure(index: usize, r: &RobotTrace, end_s: f64) -> Fig {
    let mut scale = AxisScale::default();
    for l in &r.localizers {
        for p in &l.error {
            scale.push(p[1]);
        }
    }
    let top = scale.top(0.75, 0.5);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, 260)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .margin(10)
            .caption(format!("{}: position error", r.name), ("sans-serif", 16))
            .x_label_area_size(36)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..end_s.max(1e-3), 0.0..top)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("simulated time (s)")
            .y_desc("error (m)")
            .draw()
            .map_err(err)?;
        for (k, l) in r.localizers.iter().enumerate() {
            let c = colour(colours::localizer(index as u32, k));
            chart
                .draw_series(LineSeries::new(
                    l.error.iter().map(|p| (p[0], p[1].min(top))),
                    c.stroke_width(1),
                ))
                .map_err(err)?
                .label(format!("{} {}", r.name, l.name))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// Each robot's tasks as bars from start to end: done green, failed red, unfinished grey.
pub fn timeline_figure(robots: &[RobotTrace], end_s: f64) -> Fig {
    let rows: Vec<&RobotTrace> = robots.iter().filter(|r| !r.tasks.is_empty()).collect();
    if rows.is_empty() {
        return Ok(String::new());
    }
    let height = 70 + 28 * rows.len() as u32;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let n = rows.len() as i32;
        let mut chart = ChartBuilder::on(&root)
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(90)
            // a segmented range holds its end value: rows 0..=n − 1
            .build_cartesian_2d(0.0..end_s.max(1e-3), (0..n - 1).into_segmented())
            .map_err(err)?;
        let names: Vec<String> = rows.iter().map(|r| r.name.clone()).collect();
        chart
            .configure_mesh()
            .disable_y_mesh()
            .x_desc("simulated time (s)")
            .y_label_formatter(&|v| match v {
                SegmentValue::CenterOf(i) => names.get(*i as usize).cloned().unwrap_or_default(),
                _ => String::new(),
            })
            .draw()
            .map_err(err)?;
        for (row, r) in rows.iter().enumerate() {
            for t in &r.tasks {
                let fill = match t.outcome {
                    Outcome::Done => RGBColor(44, 160, 44),
                    Outcome::Failed => RGBColor(214, 39, 40),
                    Outcome::Unfinished => RGBColor(160, 160, 160),
                };
                let row = row as i32;
                chart
                    .draw_series([Rectangle::new(
                        [
                            (t.start, SegmentValue::Exact(row)),
                            (t.end, SegmentValue::Exact(row + 1)),
                        ],
                        fill.mix(0.8).filled(),
                    )])
                    .map_err(err)?;
                chart
                    .draw_series([Rectangle::new(
                        [
                            (t.start, SegmentValue::Exact(row)),
                            (t.end, SegmentValue::Exact(row + 1)),
                        ],
                        WHITE.stroke_width(1),
                    )])
                    .map_err(err)?;
            }
        }
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// Box plots of one metric, one box per parameter set (`sets`: label and values).
pub fn box_figure(metric: &str, sets: &[(String, Vec<f64>)]) -> Fig {
    let values: Vec<f64> = sets.iter().flat_map(|(_, v)| v.iter().copied()).collect();
    if values.is_empty() {
        return Ok(String::new());
    }
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let pad = ((hi - lo) * 0.08).max(hi.abs().max(1.0) * 1e-3);
    let (lo, hi) = ((lo - pad) as f32, (hi + pad) as f32);
    let n = sets.len() as i32;
    let width = (140 + 90 * sets.len() as u32).clamp(300, WIDTH);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, 240)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let labels: Vec<String> = sets.iter().map(|(l, _)| l.clone()).collect();
        let mut chart = ChartBuilder::on(&root)
            .margin(10)
            .caption(metric, ("sans-serif", 14))
            .x_label_area_size(30)
            .y_label_area_size(60)
            // a segmented range holds its end value: boxes 0..=n − 1
            .build_cartesian_2d((0..n - 1).into_segmented(), lo..hi)
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_label_formatter(&|v| match v {
                SegmentValue::CenterOf(i) => labels.get(*i as usize).cloned().unwrap_or_default(),
                _ => String::new(),
            })
            .draw()
            .map_err(err)?;
        let c = colour(colours::robot(0));
        chart
            .draw_series(
                sets.iter()
                    .enumerate()
                    .filter(|(_, (_, v))| !v.is_empty())
                    .map(|(i, (_, v))| {
                        Boxplot::new_vertical(SegmentValue::CenterOf(i as i32), &Quartiles::new(v))
                            .width(30)
                            .style(c)
                    }),
            )
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}
