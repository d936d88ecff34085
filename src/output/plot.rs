//! Plots a person would rather look at than read, as PNG and SVG (plotters): the oedometer's
//! e(p) with the fitted Bauer curve, and a sweep's h_s against eta with the power law and the
//! paper's experimental Guamo point.
//!
//! Laying text out needs a TrueType font: the first of [`FONT_CANDIDATES`] found is used
//! (Debian/Ubuntu: `apt install fonts-dejavu-core`). Without one no plot is drawn, and the
//! error names the fix; the run's data files are unaffected.

use crate::analysis::fit::{BauerFit, Estimate, PowerLaw};
use crate::analysis::oquendo::{self, GUAMO};
use crate::protocol::CompressionPoint;
use anyhow::Context;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

/// Fonts tried, in order.
pub const FONT_CANDIDATES: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
    "/Library/Fonts/Arial.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

/// Registers a font for bitmap text once; `false` when none is found.
fn font_ready() -> bool {
    static READY: OnceLock<bool> = OnceLock::new();
    *READY.get_or_init(|| {
        FONT_CANDIDATES.iter().any(|path| match std::fs::read(path) {
            Ok(bytes) => plotters::style::register_font("sans-serif", FontStyle::Normal, Box::leak(bytes.into_boxed_slice())).is_ok(),
            Err(_) => false,
        })
    })
}

/// Draws `draw` into `<stem>.svg` and `<stem>.png`.
fn both(stem: &Path, size: (u32, u32), draw: impl Fn(&DrawingArea<SVGBackend, Shift>) -> anyhow::Result<()> + Copy, draw_png: impl Fn(&DrawingArea<BitMapBackend, Shift>) -> anyhow::Result<()>) -> anyhow::Result<()> {
    if !font_ready() {
        anyhow::bail!("{} not drawn: no TrueType font found (tried {}); fix: install one, e.g. `apt install fonts-dejavu-core`", stem.display(), FONT_CANDIDATES[0]);
    }
    let svg = stem.with_extension("svg");
    {
        let root = SVGBackend::new(&svg, size).into_drawing_area();
        draw(&root)?;
        root.present().with_context(|| format!("cannot write {}", svg.display()))?;
    }
    let png = stem.with_extension("png");
    let root = BitMapBackend::new(&png, size).into_drawing_area();
    draw_png(&root)?;
    root.present().with_context(|| format!("cannot write {}", png.display()))?;
    Ok(())
}

/// e against p, linear and logarithmic in p, with a Bauer curve per fit (labelled):
/// `<stem>.png`, `<stem>.svg`.
pub fn compression(stem: &Path, title: &str, points: &[CompressionPoint], fits: &[(&str, &BauerFit)]) -> anyhow::Result<()> {
    fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, title: &str, points: &[CompressionPoint], fits: &[(&str, &BauerFit)]) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let (left, right) = root.split_horizontally(root.dim_in_pixel().0 / 2);
        let p_kpa: Vec<f64> = points.iter().map(|c| c.pressure / 1e3).collect();
        let e: Vec<f64> = points.iter().map(|c| c.void_ratio).collect();
        let (p_min, p_max) = (p_kpa.iter().copied().fold(f64::INFINITY, f64::min), p_kpa.iter().copied().fold(0.0, f64::max));
        let (e_min, e_max) = (e.iter().copied().fold(f64::INFINITY, f64::min), e.iter().copied().fold(0.0, f64::max));
        let pad = 0.1 * (e_max - e_min).max(1e-3);
        let e_range = (e_min - pad)..(e_max + pad);
        let curve = |f: &BauerFit, p_lo: f64, p_hi: f64, log: bool| -> Vec<(f64, f64)> {
            (0..=200)
                .map(|k| {
                    let t = k as f64 / 200.0;
                    let p = if log { p_lo * (p_hi / p_lo).powf(t) } else { p_lo + (p_hi - p_lo) * t };
                    (p, f.void_ratio(p * 1e3))
                })
                .collect()
        };
        let colours = [BLUE, RED, GREEN];
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("{e:?}");
        {
            let mut chart = ChartBuilder::on(&left)
                .caption(format!("{title}: e(p)"), ("sans-serif", 18))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(56)
                .build_cartesian_2d(0.0..p_max * 1.05, e_range.clone())
                .map_err(err)?;
            chart.configure_mesh().x_desc("p (kPa)").y_desc("void ratio e").draw().map_err(err)?;
            for (k, (name, f)) in fits.iter().enumerate() {
                let c = colours[k % colours.len()];
                chart.draw_series(LineSeries::new(curve(f, 0.0, p_max * 1.05, false), c)).map_err(err)?.label(format!("Bauer, {name}: {}", f.line())).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c));
            }
            chart.draw_series(p_kpa.iter().zip(&e).map(|(&x, &y)| Circle::new((x, y), 4, BLACK.filled()))).map_err(err)?;
            chart.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).draw().map_err(err)?;
        }
        let mut chart = ChartBuilder::on(&right)
            .caption(format!("{title}: e(log p)"), ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(56)
            .build_cartesian_2d((p_min * 0.8..p_max * 1.25).log_scale(), e_range)
            .map_err(err)?;
        chart.configure_mesh().x_desc("p (kPa)").y_desc("void ratio e").draw().map_err(err)?;
        for (k, (_, f)) in fits.iter().enumerate() {
            chart.draw_series(LineSeries::new(curve(f, p_min * 0.8, p_max * 1.25, true), colours[k % colours.len()])).map_err(err)?;
        }
        chart.draw_series(p_kpa.iter().zip(&e).map(|(&x, &y)| Circle::new((x, y), 4, BLACK.filled()))).map_err(err)?;
        Ok(())
    }
    both(stem, (1200, 520), |r| draw(r, title, points, fits), |r| draw(r, title, points, fits))
}

/// h_s against eta (log-log) across a sweep, with the power law and the Guamo point; with
/// `paper`, Oquendo et al.'s Tables 2-3 and its power law beside them.
pub fn hardness(stem: &Path, title: &str, points: &[(Estimate, Estimate)], law: Option<&PowerLaw>, paper: bool) -> anyhow::Result<()> {
    fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, title: &str, points: &[(Estimate, Estimate)], law: Option<&PowerLaw>, paper: bool) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("{e:?}");
        root.fill(&WHITE).map_err(err)?;
        let published: Vec<(Estimate, Estimate)> = if paper { oquendo::TABLES.iter().map(|r| (r.eta, r.h_s)).collect() } else { Vec::new() };
        let all: Vec<&(Estimate, Estimate)> = points.iter().chain(&published).chain(std::iter::once(&GUAMO)).collect();
        // The x range reaches a decade's bounds, so that the log axis has labelled ticks.
        let x_lo = (all.iter().map(|p| (p.0.value - p.0.error).max(p.0.value * 0.5)).fold(f64::INFINITY, f64::min) * 0.8).min(0.1);
        let x_hi = (all.iter().map(|p| p.0.value + p.0.error).fold(0.0, f64::max) * 1.25).max(1.0);
        let y_lo = all.iter().map(|p| (p.1.value - p.1.error).max(p.1.value * 0.2)).fold(f64::INFINITY, f64::min) * 0.5;
        let y_hi = all.iter().map(|p| p.1.value + p.1.error).fold(0.0, f64::max) * 2.0;
        let mut chart = ChartBuilder::on(root)
            .caption(format!("{title}: h_s against eta"), ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(64)
            .build_cartesian_2d((x_lo..x_hi).log_scale().with_key_points(vec![0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 1.0]), (y_lo..y_hi).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("eta")
            .y_desc("h_s (MPa)")
            .x_labels(12)
            .x_label_formatter(&|x| format!("{x:.2}"))
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .draw()
            .map_err(err)?;
        if let Some(l) = law {
            let line: Vec<(f64, f64)> = (0..=100).map(|k| x_lo * (x_hi / x_lo).powf(k as f64 / 100.0)).map(|x| (x, l.a.value * x.powf(l.b.value))).filter(|p| p.1 >= y_lo && p.1 <= y_hi).collect();
            chart
                .draw_series(LineSeries::new(line, &BLUE))
                .map_err(err)?
                .label(l.line())
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLUE));
        }
        if paper {
            let grey = RGBColor(150, 150, 150);
            let l = oquendo::POWER_LAW;
            let line: Vec<(f64, f64)> = (0..=100).map(|k| x_lo * (x_hi / x_lo).powf(k as f64 / 100.0)).map(|x| (x, l.a.value * x.powf(l.b.value))).filter(|p| p.1 >= y_lo && p.1 <= y_hi).collect();
            chart
                .draw_series(DashedLineSeries::new(line, 6, 4, grey.stroke_width(2)))
                .map_err(err)?
                .label(format!("Oquendo et al.: {}", l.line()))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], grey));
            chart
                .draw_series(published.iter().map(|(eta, h)| ErrorBar::new_vertical(eta.value, (h.value - h.error).max(y_lo), h.value, h.value + h.error, grey.filled(), 6)))
                .map_err(err)?;
            chart
                .draw_series(published.iter().map(|(eta, h)| Rectangle::new([(eta.value * 0.985, h.value * 0.93), (eta.value * 1.015, h.value * 1.07)], grey.filled())))
                .map_err(err)?
                .label("Oquendo et al., Tables 2-3")
                .legend(move |(x, y)| Rectangle::new([(x + 4, y - 4), (x + 12, y + 4)], grey.filled()));
        }
        chart
            .draw_series(points.iter().map(|(eta, h)| ErrorBar::new_vertical(eta.value, (h.value - h.error).max(y_lo), h.value, h.value + h.error, BLACK.filled(), 6)))
            .map_err(err)?;
        chart.draw_series(points.iter().map(|(eta, h)| Circle::new((eta.value, h.value), 4, BLACK.filled()))).map_err(err)?.label("simulations").legend(|(x, y)| Circle::new((x + 8, y), 4, BLACK.filled()));
        chart
            .draw_series(std::iter::once(TriangleMarker::new((GUAMO.0.value, GUAMO.1.value), 7, RED.filled())))
            .map_err(err)?
            .label("Guamo sand (experiment): h_s = 19.1(1.1) MPa, eta = 0.57(1)")
            .legend(|(x, y)| TriangleMarker::new((x + 8, y), 6, RED.filled()));
        chart.configure_series_labels().position(SeriesLabelPosition::LowerLeft).background_style(WHITE.mix(0.8)).border_style(BLACK).draw().map_err(err)?;
        Ok(())
    }
    both(stem, (900, 640), |r| draw(r, title, points, law, paper), |r| draw(r, title, points, law, paper))
}

/// One probability density drawn by [`pdf`]: markers in its colour, labelled.
pub struct Density<'a> {
    /// Legend text.
    pub label: String,
    /// The density.
    pub pdf: &'a crate::analysis::network::Pdf,
}

/// An exponential `P = amplitude exp(-rate |x|)` from `x = start` outward on the sign of
/// `start` (`-0.0` for the negative side), drawn by [`pdf`]: solid for a fit, dashed for a
/// published value.
pub struct Tail {
    /// Where it starts (in the normalised variable).
    pub start: f64,
    /// Its rate.
    pub rate: f64,
    /// Its density at `|x| = 0`.
    pub amplitude: f64,
    /// Legend text, if it has an entry.
    pub label: Option<String>,
    /// A published value rather than a fit.
    pub published: bool,
}

/// Marker colours of the densities, in order.
const DENSITY_COLOURS: [RGBColor; 3] = [BLACK, RED, MAGENTA];

/// Probability densities on a log scale with exponential tails through them: `<stem>.png`,
/// `<stem>.svg`.
pub fn pdf(stem: &Path, title: &str, x_label: &str, densities: &[Density], tails: &[Tail]) -> anyhow::Result<()> {
    fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, title: &str, x_label: &str, densities: &[Density], tails: &[Tail]) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("{e:?}");
        root.fill(&WHITE).map_err(err)?;
        let points: Vec<Vec<(f64, f64)>> = densities.iter().map(|d| d.pdf.x.iter().zip(&d.pdf.p).filter(|(_, p)| **p > 0.0).map(|(x, p)| (*x, *p)).collect()).collect();
        let all = || points.iter().flatten();
        let x_lo = densities.iter().filter_map(|d| d.pdf.x.first().copied()).fold(f64::INFINITY, f64::min);
        let x_hi = densities.iter().filter_map(|d| d.pdf.x.last().copied()).fold(f64::NEG_INFINITY, f64::max);
        let (x_lo, x_hi) = if x_lo < x_hi { (x_lo, x_hi) } else { (0.0, 1.0) };
        let p_hi = all().map(|q| q.1).fold(1e-3, f64::max) * 2.0;
        let p_lo = all().map(|q| q.1).fold(f64::INFINITY, f64::min).min(p_hi / 10.0) / 2.0;
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(64)
            .build_cartesian_2d(x_lo..x_hi, (p_lo..p_hi).log_scale())
            .map_err(err)?;
        chart.configure_mesh().x_desc(x_label).y_desc("probability density").draw().map_err(err)?;
        for (k, (d, pts)) in densities.iter().zip(&points).enumerate() {
            let colour = DENSITY_COLOURS[k % DENSITY_COLOURS.len()];
            chart
                .draw_series(pts.iter().map(|&(x, p)| Circle::new((x, p), 4, colour.filled())))
                .map_err(err)?
                .label(d.label.clone())
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, colour.filled()));
        }
        for t in tails {
            let end = if t.start.is_sign_positive() { x_hi } else { x_lo };
            let line: Vec<(f64, f64)> = (0..=50).map(|k| t.start + (end - t.start) * k as f64 / 50.0).map(|x| (x, t.amplitude * (-t.rate * x.abs()).exp())).filter(|q| q.1 > p_lo).collect();
            let colour = if t.published { RGBColor(110, 110, 110) } else { BLUE };
            let drawn = if t.published { chart.draw_series(DashedLineSeries::new(line, 6, 4, colour.into())) } else { chart.draw_series(LineSeries::new(line, colour)) }.map_err(err)?;
            if let Some(label) = &t.label {
                drawn.label(label.clone()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour));
            }
        }
        chart.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).draw().map_err(err)?;
        Ok(())
    }
    both(stem, (800, 600), |r| draw(r, title, x_label, densities, tails), |r| draw(r, title, x_label, densities, tails))
}

/// A slice of the packing, about three diameters thick across y through the middle, seen
/// along y: the bonds as segments between centres (width proportional to the force;
/// compressive red, tensile green), and the grains coloured by the sign of their pressure
/// (red positive, blue negative).
pub fn slices(stem_network: &Path, stem_pressure: &Path, title: &str, frame: &crate::engine::Frame, pressures: &[f64]) -> anyhow::Result<()> {
    let n = frame.radius.len();
    let d_mean = 2.0 * frame.radius.iter().sum::<f64>() / n.max(1) as f64;
    let (y_lo, y_hi) = frame.position.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| (l.min(p[1]), h.max(p[1])));
    let mid = 0.5 * (y_lo + y_hi);
    let in_slice: Vec<bool> = frame.position.iter().map(|p| (p[1] - mid).abs() <= 1.5 * d_mean).collect();
    let (mut x0, mut x1, mut z0, mut z1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for i in (0..n).filter(|&i| in_slice[i]) {
        let (p, r) = (frame.position[i], frame.radius[i]);
        (x0, x1, z0, z1) = (x0.min(p[0] - r), x1.max(p[0] + r), z0.min(p[2] - r), z1.max(p[2] + r));
    }
    let bonds: Vec<(usize, usize, f64)> = frame
        .contacts
        .as_deref()
        .unwrap_or(&[])
        .iter()
        .filter(|c| c.normal_force != 0.0 && in_slice[c.i as usize] && in_slice[c.j as usize])
        // A bond across a periodic boundary would cross the picture: leave it out.
        .filter(|c| {
            let (a, b) = (frame.position[c.i as usize], frame.position[c.j as usize]);
            ((a[0] - b[0]).powi(2) + (a[2] - b[2]).powi(2)).sqrt() < 2.0 * (frame.radius[c.i as usize] + frame.radius[c.j as usize])
        })
        .map(|c| (c.i as usize, c.j as usize, c.normal_force))
        .collect();
    let f_max = bonds.iter().map(|b| b.2.abs()).fold(1e-300, f64::max);
    let size = (900u32, (900.0 * (z1 - z0) / (x1 - x0)).clamp(300.0, 1400.0) as u32);
    fn network<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, title: &str, frame: &crate::engine::Frame, bonds: &[(usize, usize, f64)], f_max: f64, range: (f64, f64, f64, f64)) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("{e:?}");
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(root).caption(format!("{title}: force network (red compressive, green tensile)"), ("sans-serif", 16)).margin(10).build_cartesian_2d(range.0..range.1, range.2..range.3).map_err(err)?;
        chart
            .draw_series(bonds.iter().map(|&(i, j, f)| {
                let color = if f > 0.0 { RED } else { GREEN };
                let width = (1.0 + 7.0 * f.abs() / f_max) as u32;
                PathElement::new(vec![(frame.position[i][0], frame.position[i][2]), (frame.position[j][0], frame.position[j][2])], color.stroke_width(width))
            }))
            .map_err(err)?;
        Ok(())
    }
    fn pressure<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, title: &str, frame: &crate::engine::Frame, in_slice: &[bool], pressures: &[f64], range: (f64, f64, f64, f64)) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("{e:?}");
        root.fill(&WHITE).map_err(err)?;
        let mut chart = ChartBuilder::on(root).caption(format!("{title}: particle pressure sign (red > 0, blue < 0)"), ("sans-serif", 16)).margin(10).build_cartesian_2d(range.0..range.1, range.2..range.3).map_err(err)?;
        let px_per_m = root.dim_in_pixel().0 as f64 / (range.1 - range.0);
        chart
            .draw_series((0..pressures.len()).filter(|&i| in_slice[i]).map(|i| {
                let color = if pressures[i] > 0.0 { RED } else if pressures[i] < 0.0 { BLUE } else { BLACK };
                Circle::new((frame.position[i][0], frame.position[i][2]), (frame.radius[i] * px_per_m).max(1.0) as u32, color.mix(0.8).filled())
            }))
            .map_err(err)?;
        Ok(())
    }
    let range = (x0, x1, z0, z1);
    both(stem_network, size, |r| network(r, title, frame, &bonds, f_max, range), |r| network(r, title, frame, &bonds, f_max, range))?;
    both(stem_pressure, size, |r| pressure(r, title, frame, &in_slice, pressures, range), |r| pressure(r, title, frame, &in_slice, pressures, range))
}

/// Wall time against error (log-log), one line per series (name, (error, seconds) points):
/// the cheapest setting for an error budget is the lowest point left of it.
pub fn speed_error(stem: &Path, title: &str, x_label: &str, series: &[(String, Vec<(f64, f64)>)]) -> anyhow::Result<()> {
    fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, title: &str, x_label: &str, series: &[(String, Vec<(f64, f64)>)]) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("{e:?}");
        root.fill(&WHITE).map_err(err)?;
        let points = || series.iter().flat_map(|(_, p)| p.iter().copied()).filter(|(e, t)| *e > 0.0 && *t > 0.0);
        let (x_lo, x_hi) = points().fold((f64::INFINITY, 0.0f64), |(lo, hi), (e, _)| (lo.min(e), hi.max(e)));
        let (y_lo, y_hi) = points().fold((f64::INFINITY, 0.0f64), |(lo, hi), (_, t)| (lo.min(t), hi.max(t)));
        if !(x_lo < x_hi && y_lo < y_hi) {
            anyhow::bail!("nothing to plot for {title}");
        }
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(64)
            .build_cartesian_2d((x_lo / 2.0..x_hi * 2.0).log_scale(), (y_lo / 1.5..y_hi * 1.5).log_scale())
            .map_err(err)?;
        // Two significant digits: log-scale ticks such as 0.30000000000000004 print as 0.3.
        let short = |v: &f64| format!("{}", format!("{v:.1e}").parse::<f64>().unwrap_or(*v));
        chart.configure_mesh().x_desc(x_label).y_desc("wall time (s)").x_labels(6).y_labels(8).x_label_formatter(&|x| format!("{x:.0e}")).y_label_formatter(&short).draw().map_err(err)?;
        for (k, (name, pts)) in series.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            let pts: Vec<(f64, f64)> = pts.iter().copied().filter(|(e, t)| *e > 0.0 && *t > 0.0).collect();
            chart.draw_series(LineSeries::new(pts.clone(), color.stroke_width(2))).map_err(err)?.label(name.as_str()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2)));
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled()))).map_err(err)?;
        }
        chart.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).draw().map_err(err)?;
        Ok(())
    }
    both(stem, (900, 640), |r| draw(r, title, x_label, series), |r| draw(r, title, x_label, series))
}
