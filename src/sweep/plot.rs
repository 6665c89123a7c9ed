//! The time-vs-size plot of a sweep (SVG, `plotters`): total time per mesh against its
//! faces, log–log, one colour per outcome.

use plotters::prelude::*;

use super::merge::Merged;
use super::record::Outcome;
use super::{Result, SweepError};

fn colour(o: Outcome) -> RGBColor {
    match o {
        Outcome::Ok => RGBColor(0x1f, 0x77, 0xb4),
        Outcome::Refused => RGBColor(0x99, 0x99, 0x99),
        Outcome::Failed => RGBColor(0xd6, 0x27, 0x28),
        Outcome::Crashed => RGBColor(0x94, 0x67, 0xbd),
        Outcome::Timeout => RGBColor(0xff, 0x7f, 0x0e),
    }
}

/// A tick label without trailing zeros: 1, 10, 0.1.
fn label(v: f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The SVG text of the plot.
pub fn time_vs_size(merged: &Merged) -> Result<String> {
    let points: Vec<(Outcome, f64, f64)> = merged
        .records
        .iter()
        .filter_map(|r| {
            let faces = *r.sizes.get("faces")? as f64;
            let ms = r.total_ms()?;
            Some((r.outcome, faces.max(1.0), ms.max(1e-3)))
        })
        .collect();
    let range = |v: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
        if lo.is_finite() { (lo / 1.5, hi * 1.5) } else { (1.0, 10.0) }
    };
    let (x0, x1) = range(&mut points.iter().map(|p| p.1));
    let (y0, y1) = range(&mut points.iter().map(|p| p.2));
    let mut svg = String::new();
    let err = |e: &dyn std::fmt::Display| SweepError::Plot(e.to_string());
    // Text is measured with a real font (the same one the reports use).
    crate::report::plot::ensure_font().map_err(|e| err(&e))?;
    {
        let root = SVGBackend::with_string(&mut svg, (800, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                format!("texgeo sweep: {} — time per mesh against size", merged.info.task),
                ("sans-serif", 20),
            )
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("faces")
            .y_desc("total time per mesh (ms)")
            .x_label_formatter(&|x| label(*x))
            .y_label_formatter(&|y| label(*y))
            .draw()
            .map_err(|e| err(&e))?;
        for o in Outcome::ALL {
            let c = colour(o);
            let mine: Vec<(f64, f64)> = points.iter().filter(|p| p.0 == o).map(|p| (p.1, p.2)).collect();
            if mine.is_empty() {
                continue;
            }
            chart
                .draw_series(mine.iter().map(|&p| Circle::new(p, 3, c.filled())))
                .map_err(|e| err(&e))?
                .label(format!("{o} ({})", mine.len()))
                .legend(move |(x, y)| Circle::new((x, y), 4, c.filled()));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))?;
    }
    Ok(svg)
}
