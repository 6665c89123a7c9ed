//! Line charts for reports (`plotters`), as SVG and as PNG from the same drawing code:
//! today's curves solid with filled markers, the thesis' dashed with hollow ones.
//!
//! Text needs a TrueType font to measure (SVG) and to draw (PNG). None is embedded: the
//! first chart loads one from `TEXGEO_FONT` or the usual system places (Debian's
//! `fonts-dejavu-core`, which `tools/setup` installs), and says so when there is none.

use std::ops::Range;
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use plotters::prelude::*;

/// Where a sans-serif TrueType font is looked for, after `TEXGEO_FONT`.
pub const FONT_PATHS: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
];

/// Loads and registers the plots' font once; the error says how to get one.
pub fn ensure_font() -> Result<(), String> {
    static FONT: OnceLock<Result<(), String>> = OnceLock::new();
    FONT.get_or_init(|| {
        let candidates: Vec<String> = std::env::var("TEXGEO_FONT")
            .into_iter()
            .chain(FONT_PATHS.iter().map(|p| p.to_string()))
            .collect();
        for path in &candidates {
            let Ok(bytes) = std::fs::read(path) else { continue };
            // plotters keeps fonts for the life of the process.
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            return plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
                .map_err(|_| format!("{path}: not a usable TrueType font (set TEXGEO_FONT to another)"));
        }
        Err(format!(
            "plots need a TrueType font and none was found ({}); install fonts-dejavu-core (tools/setup does) \
             or set TEXGEO_FONT=/path/to/font.ttf",
            candidates.join(", ")
        ))
    })
    .clone()
}

/// One curve.
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// The thesis' numbers (dashed, hollow markers) rather than today's.
    pub thesis: bool,
    /// Index into the palette; a thesis curve takes the colour of today's curve it matches.
    pub colour: usize,
}

/// A chart: title, axes and curves.
#[derive(Clone, Debug)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    pub series: Vec<Series>,
}

/// The most curves one chart holds: more and a reader cannot tell their colours and
/// dash patterns apart ([`Chart::split`] makes several charts of a larger one).
pub const MOST_SERIES: usize = 8;

/// Size of every chart, pixels: the plot, and the legend in a column on its right.
pub const WIDTH: u32 = 1000;
pub const HEIGHT: u32 = 560;
const LEGEND: u32 = 250;

const PALETTE: [RGBColor; 10] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x7f, 0x7f, 0x7f),
    RGBColor(0xbc, 0xbd, 0x22),
    RGBColor(0x17, 0xbe, 0xcf),
];

/// A tick label without trailing zeros: 1, 10, 0.1, 2.5e-5; thousands grouped by thin
/// spaces (10 000, 1 000 000) so a log axis reads alike from end to end.
fn label(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e9) {
        return format!("{v:.0e}");
    }
    if v.abs() >= 1e4 && v.fract() == 0.0 {
        let digits = format!("{:.0}", v.abs());
        let mut grouped = String::new();
        for (i, c) in digits.chars().enumerate() {
            if i > 0 && (digits.len() - i) % 3 == 0 {
                grouped.push('\u{2009}');
            }
            grouped.push(c);
        }
        return if v < 0.0 { format!("-{grouped}") } else { grouped };
    }
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The ticks of a log axis over `range`: the data's decades (1, 10, 100, …), with 2 and
/// 5 between them when the range spans less than two decades, thinned so at most
/// [`MOST_TICKS`] carry a label (labels never overlap); the light grid lines at every
/// multiple 2…9 of a decade.
fn log_ticks(range: &Range<f64>) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = (range.start.max(f64::MIN_POSITIVE), range.end.max(f64::MIN_POSITIVE));
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let inside = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    let decades: Vec<f64> = (first..=last).map(|k| 10f64.powi(k)).filter(inside).collect();
    let steps: &[f64] = if decades.len() >= 2 { &[1.0] } else { &[1.0, 2.0, 5.0] };
    let mut bold: Vec<f64> =
        (first..=last).flat_map(|k| steps.iter().map(move |m| m * 10f64.powi(k))).filter(inside).collect();
    let stride = bold.len().div_ceil(MOST_TICKS).max(1);
    bold = bold.into_iter().step_by(stride).collect();
    let light = (first..=last)
        .flat_map(|k| (2..10).map(move |m| f64::from(m) * 10f64.powi(k)))
        .filter(inside)
        .filter(|v| !bold.contains(v))
        .collect();
    (bold, light)
}

/// The most labelled ticks on an axis.
const MOST_TICKS: usize = 8;

impl Chart {
    /// A chart with both axes logarithmic.
    pub fn loglog(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
        series: Vec<Series>,
    ) -> Chart {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_log: true,
            y_log: true,
            series,
        }
    }

    /// This chart, or when it holds more than [`MOST_SERIES`] curves, several charts
    /// ("(1 of 2)", …) that split it between colours: a thesis curve stays with today's
    /// curve of its colour.
    pub fn split(&self) -> Vec<Chart> {
        if self.series.len() <= MOST_SERIES {
            return vec![self.clone()];
        }
        let mut groups: Vec<Vec<Series>> = Vec::new();
        for s in &self.series {
            match groups.iter_mut().find(|g| g[0].colour == s.colour) {
                Some(g) => g.push(s.clone()),
                None => groups.push(vec![s.clone()]),
            }
        }
        let mut parts: Vec<Vec<Series>> = Vec::new();
        for g in groups {
            match parts.last_mut() {
                Some(p) if p.len() + g.len() <= MOST_SERIES => p.extend(g),
                _ => parts.push(g),
            }
        }
        let n = parts.len();
        parts
            .into_iter()
            .enumerate()
            .map(|(i, series)| Chart {
                title: format!("{} ({} of {n})", self.title, i + 1),
                series,
                ..self.clone()
            })
            .collect()
    }

    fn points(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .filter(|p| p.0.is_finite() && p.1.is_finite())
    }

    /// A chart with more curves than a reader can tell apart is not drawn ([`Chart::split`]).
    fn check(&self) -> Result<(), String> {
        if self.series.len() > MOST_SERIES {
            return Err(format!(
                "{}: {} curves, more than the {MOST_SERIES} a reader can tell apart",
                self.title,
                self.series.len()
            ));
        }
        Ok(())
    }

    /// Axis range over the data, padded; positive only on a log axis.
    fn range(&self, log: bool, pick: impl Fn((f64, f64)) -> f64) -> Range<f64> {
        let values = self.points().map(pick).filter(|v| !log || *v > 0.0);
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        if !lo.is_finite() {
            return if log { 0.1..10.0 } else { 0.0..1.0 };
        }
        if log {
            (lo / 1.6)..(hi * 1.6)
        } else {
            let pad = ((hi - lo) * 0.08).max(hi.abs() * 0.05).max(1e-9);
            (lo - pad)..(hi + pad)
        }
    }

    /// The chart as an SVG document.
    pub fn svg(&self) -> Result<String, String> {
        self.check()?;
        ensure_font()?;
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area();
            self.draw(&root)?;
            root.present().map_err(|e| e.to_string())?;
        }
        Ok(svg)
    }

    /// The chart as a PNG file's bytes.
    pub fn png(&self) -> Result<Vec<u8>, String> {
        self.check()?;
        ensure_font()?;
        let mut rgb = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (WIDTH, HEIGHT)).into_drawing_area();
            self.draw(&root)?;
            root.present().map_err(|e| e.to_string())?;
        }
        let image = image::RgbImage::from_raw(WIDTH, HEIGHT, rgb).ok_or("plot buffer size")?;
        let mut png = Vec::new();
        image
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .map_err(|e| e.to_string())?;
        Ok(png)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let (x, y) = (self.range(self.x_log, |p| p.0), self.range(self.y_log, |p| p.1));
        let log = |r: Range<f64>| {
            let (bold, light) = log_ticks(&r);
            r.log_scale().with_key_points(bold).with_light_points(light)
        };
        match (self.x_log, self.y_log) {
            (true, true) => self.draw_on(root, log(x), log(y)),
            (true, false) => self.draw_on(root, log(x), y),
            (false, true) => self.draw_on(root, x, log(y)),
            (false, false) => self.draw_on(root, x, y),
        }
    }

    fn draw_on<DB, X, Y>(&self, root: &DrawingArea<DB, Shift>, x: X, y: Y) -> Result<(), String>
    where
        DB: DrawingBackend,
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let err = |e: &dyn std::fmt::Display| e.to_string();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let (plot, legend) = root.split_horizontally(WIDTH - LEGEND);
        let mut chart = ChartBuilder::on(&plot)
            .caption(&self.title, ("sans-serif", 20))
            .margin(14)
            .x_label_area_size(48)
            .y_label_area_size(78)
            .build_cartesian_2d(x, y)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .x_label_formatter(&|v| label(*v))
            .y_label_formatter(&|v| label(*v))
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(|e| err(&e))?;
        for s in &self.series {
            let c = PALETTE[s.colour % PALETTE.len()];
            let mut pts: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|p| {
                    p.0.is_finite()
                        && p.1.is_finite()
                        && (!self.x_log || p.0 > 0.0)
                        && (!self.y_log || p.1 > 0.0)
                })
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            if pts.is_empty() {
                continue;
            }
            if s.thesis {
                chart
                    .draw_series(DashedLineSeries::new(pts.clone(), 7, 5, c.stroke_width(2)))
                    .map_err(|e| err(&e))?;
                chart
                    .draw_series(pts.iter().map(|&p| TriangleMarker::new(p, 5, c.stroke_width(1))))
                    .map_err(|e| err(&e))?;
            } else {
                chart.draw_series(LineSeries::new(pts.clone(), c.stroke_width(2))).map_err(|e| err(&e))?;
                chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled()))).map_err(|e| err(&e))?;
            }
        }
        // The legend in its own column, so it never hides a curve.
        for (i, s) in self.series.iter().enumerate() {
            let c = PALETTE[s.colour % PALETTE.len()];
            let y = 50 + 20 * i as i32;
            if s.thesis {
                for x in [8, 22] {
                    legend
                        .draw(&PathElement::new(vec![(x, y), (x + 9, y)], c.stroke_width(2)))
                        .map_err(|e| err(&e))?;
                }
                legend.draw(&TriangleMarker::new((20, y), 5, c.stroke_width(1))).map_err(|e| err(&e))?;
            } else {
                legend
                    .draw(&PathElement::new(vec![(8, y), (32, y)], c.stroke_width(2)))
                    .map_err(|e| err(&e))?;
                legend.draw(&Circle::new((20, y), 4, c.filled())).map_err(|e| err(&e))?;
            }
            legend
                .draw(&Text::new(s.label.clone(), (40, y - 7), ("sans-serif", 13).into_font().color(&BLACK)))
                .map_err(|e| err(&e))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart(x_log: bool) -> Chart {
        Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            x_log,
            y_log: true,
            series: vec![
                Series {
                    label: "today".into(),
                    points: vec![(1.0, 1.0), (10.0, 5.0)],
                    thesis: false,
                    colour: 0,
                },
                Series {
                    label: "thesis".into(),
                    points: vec![(1.0, 2.0), (10.0, 20.0)],
                    thesis: true,
                    colour: 0,
                },
            ],
        }
    }

    #[test]
    fn charts_render_as_svg_and_png() {
        for log in [false, true] {
            let svg = chart(log).svg().unwrap();
            assert!(svg.contains("<svg") && svg.contains("today") && svg.contains("thesis"));
            let png = chart(log).png().unwrap();
            let img = image::load_from_memory(&png).unwrap().to_rgb8();
            assert_eq!(img.dimensions(), (WIDTH, HEIGHT));
            assert!(img.pixels().any(|p| p.0 != [255, 255, 255]), "something is drawn");
        }
    }

    #[test]
    fn log_ticks_sit_at_the_data_decades_and_stay_few() {
        let (bold, light) = log_ticks(&(0.5..2000.0));
        assert_eq!(bold, vec![1.0, 10.0, 100.0, 1000.0]);
        assert!(light.contains(&2.0) && light.contains(&500.0) && !light.contains(&10.0));
        // Less than two decades: 1-2-5 steps.
        assert_eq!(log_ticks(&(1.5..30.0)).0, vec![2.0, 5.0, 10.0, 20.0]);
        // Twenty decades: thinned to at most MOST_TICKS labels.
        let (bold, _) = log_ticks(&(1e-10..1e10));
        assert!(bold.len() <= MOST_TICKS && bold.len() >= 4, "{bold:?}");
        assert!(bold.iter().all(|v| (v.log10() - v.log10().round()).abs() < 1e-9), "{bold:?}");
    }

    #[test]
    fn a_crowded_chart_is_refused_and_split_between_colours() {
        let mut c = chart(true);
        c.series = (0..7)
            .flat_map(|i| {
                [false, true].map(|thesis| Series {
                    label: format!("s{i}{thesis}"),
                    points: vec![(1.0, 1.0 + i as f64), (10.0, 2.0)],
                    thesis,
                    colour: i,
                })
            })
            .collect();
        assert!(c.svg().unwrap_err().contains("14 curves"));
        let parts = c.split();
        assert_eq!(parts.len(), 2);
        assert!(parts.iter().all(|p| p.series.len() <= MOST_SERIES && p.svg().is_ok()));
        assert_eq!(parts.iter().map(|p| p.series.len()).sum::<usize>(), 14);
        // Today's curve and the thesis' of one colour stay on one chart.
        for p in &parts {
            for s in &p.series {
                assert_eq!(p.series.iter().filter(|t| t.colour == s.colour).count(), 2);
            }
        }
        assert!(parts[1].title.ends_with("(2 of 2)"));
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(label(10.0), "10");
        assert_eq!(label(0.25), "0.25");
        assert_eq!(label(3e-5), "3e-5");
        assert_eq!(label(1e6), "1\u{2009}000\u{2009}000");
        assert_eq!(label(10_000.0), "10\u{2009}000");
        assert_eq!(label(1000.0), "1000");
    }
}
