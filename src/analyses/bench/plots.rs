//! The benchmark's PNG plots (plotters, bitmap backend). Text is drawn with DejaVu
//! Sans compiled into the binary (the `dejavu` crate, through plotters' ab_glyph
//! feature), so no system font or font library is needed.
//!
//! - `error_vs_wall.png`: error against wall time, log–log, one series per
//!   configuration and time-sweep point, through its grids (the speed/accuracy
//!   trade);
//! - `newton_per_step.png`: Newton iterations per step against unknowns;
//! - `krylov_per_newton.png`: Krylov iterations per Newton iteration against unknowns;
//! - `residual_history.png`: normalised residual of every Newton iteration of one
//!   run per configuration (the largest grid, first time-sweep point).
//!
//! A plot without data still gets written, with a note saying why it is empty.

use super::row::Row;
use crate::output::Table;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

const SIZE: (u32, u32) = (1000, 650);
const FONT: &str = "sans-serif";

/// Ten distinguishable colours (the "tab10" palette).
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// A named series of points.
struct Series {
    name: String,
    points: Vec<(f64, f64)>,
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type PlotResult = Result<(), String>;

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font, so this cannot fail.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
    });
}

/// Draw all plots into `out`; returns the files written.
pub fn draw_all(rows: &[Row], out: &Path) -> Result<Vec<PathBuf>, String> {
    register_font();
    let mut files = Vec::new();
    let ran: Vec<&Row> = rows.iter().filter(|r| r.unknowns.is_some()).collect();

    let path = out.join("error_vs_wall.png");
    let series = by_configuration_and_time(&ran, |r| {
        r.is_ok().then_some(())?;
        Some((r.wall_seconds?, r.error?))
    });
    plot(
        &path,
        "Error against wall time",
        "wall time of the run (s)",
        "error",
        true,
        true,
        &series,
        "no completed run has an error (does the scene have a [reference]?)",
    )?;
    files.push(path);

    let path = out.join("newton_per_step.png");
    let series =
        by_configuration_and_time(&ran, |r| Some((r.unknowns? as f64, r.newton_per_step()?)));
    plot(
        &path,
        "Newton iterations per step",
        "unknowns",
        "Newton iterations per step",
        true,
        false,
        &series,
        "no implicit run",
    )?;
    files.push(path);

    let path = out.join("krylov_per_newton.png");
    let series =
        by_configuration_and_time(&ran, |r| Some((r.unknowns? as f64, r.krylov_per_newton()?)));
    plot(
        &path,
        "Krylov iterations per Newton iteration",
        "unknowns",
        "Krylov iterations per Newton iteration",
        true,
        false,
        &series,
        "no run reports Krylov iterations (newton.csv has no krylov column)",
    )?;
    files.push(path);

    let path = out.join("residual_history.png");
    let series = residual_histories(&ran, out);
    plot(
        &path,
        "Newton residual histories (largest grid, first time point)",
        "Newton iteration (cumulative over the run)",
        "normalised residual",
        false,
        true,
        &series,
        "no implicit run wrote newton.csv",
    )?;
    files.push(path);
    Ok(files)
}

/// One series per configuration and time-sweep point.
fn by_configuration_and_time(
    rows: &[&Row],
    point: impl Fn(&Row) -> Option<(f64, f64)>,
) -> Vec<Series> {
    group(
        rows,
        |r| format!("{} {}", r.configuration, time_label(r)),
        point,
    )
}

fn time_label(r: &Row) -> String {
    match (r.load_steps, r.dt) {
        (Some(n), _) => format!("{n} load steps"),
        (None, Some(dt)) if r.solver != "explicit" => format!("dt {dt:.3e}"),
        _ => String::new(),
    }
}

fn group(
    rows: &[&Row],
    key: impl Fn(&Row) -> String,
    point: impl Fn(&Row) -> Option<(f64, f64)>,
) -> Vec<Series> {
    let mut out: Vec<Series> = Vec::new();
    for r in rows {
        let Some(p) = point(r) else { continue };
        let name = key(r);
        match out.iter_mut().find(|s| s.name == name) {
            Some(s) => s.points.push(p),
            None => out.push(Series {
                name,
                points: vec![p],
            }),
        }
    }
    for s in &mut out {
        s.points.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    out
}

/// For each configuration, the run with the most unknowns (the first such row, i.e.
/// the first time-sweep point): its residuals from newton.csv.
fn residual_histories(rows: &[&Row], out: &Path) -> Vec<Series> {
    let mut series = Vec::new();
    let mut names: Vec<&str> = rows.iter().map(|r| r.configuration.as_str()).collect();
    names.dedup();
    for name in names {
        let candidates = rows.iter().filter(|r| r.configuration == name);
        let Some(best) = candidates.fold(None::<&Row>, |best, r| match best {
            Some(b) if b.unknowns >= r.unknowns => Some(b),
            _ => Some(r),
        }) else {
            continue;
        };
        let Ok(newton) = Table::read(&out.join(&best.run_dir).join("newton.csv")) else {
            continue;
        };
        let Ok(residual) = newton.column("residual") else {
            continue;
        };
        let points: Vec<(f64, f64)> = residual
            .iter()
            .enumerate()
            .filter(|(_, r)| **r > 0.0 && r.is_finite())
            .map(|(i, r)| ((i + 1) as f64, *r))
            .collect();
        if !points.is_empty() {
            series.push(Series {
                name: format!("{name} ({}, {})", best.cells, time_label(best)),
                points,
            });
        }
    }
    series
}

/// Axis range over the data, padded; for a log axis only positive values count.
fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let v: Vec<f64> = values
        .filter(|x| x.is_finite() && (!log || *x > 0.0))
        .collect();
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        let pad = if hi / lo < 10.0 { 2.0 } else { 1.3 };
        (lo / pad, hi * pad)
    } else {
        let pad = if hi > lo {
            0.08 * (hi - lo)
        } else {
            0.5 * lo.abs().max(1.0)
        };
        (
            (lo - pad).min(if lo >= 0.0 { 0.0 } else { lo - pad }),
            hi + pad,
        )
    }
}

#[allow(clippy::too_many_arguments)]
fn plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    log_x: bool,
    log_y: bool,
    series: &[Series],
    empty_note: &str,
) -> PlotResult {
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let points = || series.iter().flat_map(|s| s.points.iter());
    let xr = range(points().map(|p| p.0), log_x);
    let yr = range(points().map(|p| p.1), log_y);
    match (log_x, log_y) {
        (true, true) => draw(
            &root,
            title,
            x_label,
            y_label,
            (xr.0..xr.1).log_scale(),
            (yr.0..yr.1).log_scale(),
            series,
        ),
        (true, false) => draw(
            &root,
            title,
            x_label,
            y_label,
            (xr.0..xr.1).log_scale(),
            yr.0..yr.1,
            series,
        ),
        (false, true) => draw(
            &root,
            title,
            x_label,
            y_label,
            xr.0..xr.1,
            (yr.0..yr.1).log_scale(),
            series,
        ),
        (false, false) => draw(
            &root,
            title,
            x_label,
            y_label,
            xr.0..xr.1,
            yr.0..yr.1,
            series,
        ),
    }?;
    if series.is_empty() {
        root.draw(&Text::new(
            format!("no data: {empty_note}"),
            (120, SIZE.1 as i32 / 2),
            (FONT, 20).into_font().color(&RED),
        ))
        .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
}

fn draw<X, Y>(
    root: &Area,
    title: &str,
    x_label: &str,
    y_label: &str,
    x: X,
    y: Y,
    series: &[Series],
) -> PlotResult
where
    X: plotters::coord::ranged1d::AsRangedCoord<Value = f64>,
    Y: plotters::coord::ranged1d::AsRangedCoord<Value = f64>,
    X::CoordDescType: plotters::coord::ranged1d::ValueFormatter<f64>,
    Y::CoordDescType: plotters::coord::ranged1d::ValueFormatter<f64>,
{
    let e = |e: DrawingAreaErrorKind<_>| e.to_string();
    let mut chart = ChartBuilder::on(root)
        .caption(title, (FONT, 24))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x, y)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 17))
        .draw()
        .map_err(e)?;
    for (i, s) in series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let style = ShapeStyle::from(&colour).stroke_width(2);
        chart
            .draw_series(LineSeries::new(s.points.iter().copied(), style))
            .map_err(e)?
            .label(s.name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        // Markers distinguish series that share a colour (more than ten series).
        let filled = (i / COLOURS.len()) % 2 == 0;
        chart
            .draw_series(s.points.iter().map(|&p| {
                let st = if filled {
                    colour.filled()
                } else {
                    colour.stroke_width(2)
                };
                Circle::new(p, 4, st)
            }))
            .map_err(e)?;
    }
    if !series.is_empty() {
        chart
            .configure_series_labels()
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(e)?;
    }
    Ok(())
}

/// An axis label: up to four significant digits, plain for moderate magnitudes.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() {
        return format!("{v}");
    }
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.1e}").replace(".0e", "e");
    }
    let p = 10f64.powi(3 - a.log10().floor() as i32);
    format!("{}", (v * p).round() / p)
}
