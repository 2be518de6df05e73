//! PNG line plots of learning curves, drawn with plotters. Labels use DejaVu Sans, which
//! scripts/setup installs (Debian: fonts-dejavu-core).

use std::path::Path;
use std::sync::OnceLock;

use plotters::prelude::*;

const FONT_PATHS: [&str; 2] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
];

/// Registers the label font once; an error names the package to install.
fn font() -> Result<(), String> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            let bytes = FONT_PATHS
                .iter()
                .find_map(|p| std::fs::read(p).ok())
                .ok_or_else(|| {
                    "no DejaVu Sans font for plot labels: apt-get install fonts-dejavu-core"
                        .to_string()
                })?;
            plotters::style::register_font(
                "sans-serif",
                FontStyle::Normal,
                Box::leak(bytes.into_boxed_slice()),
            )
            .map_err(|_| "DejaVu Sans could not be read".to_string())
        })
        .clone()
}

/// Matplotlib's "tab10" colours: distinct from each other and legible on white.
const TAB10: [RGBColor; 10] = [
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

/// One curve: a label, points, and an optional band (lower, upper) around them.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub band: Option<Vec<(f64, f64, f64)>>,
}

const LEGEND_FONT: (&str, u32) = ("sans-serif", 14);

/// Breaks `label` at spaces into lines no wider than `width` pixels in the legend's font, so a
/// long label wraps inside the legend panel instead of running off the image. A single word
/// wider than the panel keeps a line of its own.
fn wrapped<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    label: &str,
    width: u32,
) -> Result<Vec<String>, String> {
    let mut lines: Vec<String> = Vec::new();
    for word in label.split_whitespace() {
        let joined = match lines.last() {
            Some(line) => format!("{line} {word}"),
            None => word.to_string(),
        };
        let (joined_width, _) = area
            .estimate_text_size(&joined, &LEGEND_FONT.into_text_style(area))
            .map_err(|e| e.to_string())?;
        match lines.last_mut() {
            Some(line) if joined_width <= width => *line = joined,
            _ => lines.push(word.to_string()),
        }
    }
    Ok(lines)
}

/// Draws `series` against a shared x axis into a 1000x500 PNG, y from 0 to `y_max`, under a
/// title across the whole image, with the legend in a panel of its own on the right, where it
/// cannot cover a curve. Series without points are left out.
pub fn line_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    y_max: f64,
    series: &[Series],
) -> Result<(), String> {
    font()?;
    let x_max = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .fold(1.0, f64::max);
    let mut temporary = path.to_path_buf();
    temporary.set_extension("tmp.png");
    {
        let root = BitMapBackend::new(&temporary, (1000, 500)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        // The title spans the whole image, so that a long one is not cut at the plot's edges.
        let body = root
            .titled(title, ("sans-serif", 22))
            .map_err(|e| e.to_string())?;
        let (plot_area, legend_area) = body.split_horizontally(760);
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..x_max, 0.0..y_max)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .draw()
            .map_err(|e| e.to_string())?;
        let drawn = series.iter().filter(|s| !s.points.is_empty());
        let mut legend_y = 60;
        let label_width = legend_area.dim_in_pixel().0 - 40;
        for (i, s) in drawn.enumerate() {
            let colour = TAB10[i % TAB10.len()].to_rgba();
            if let Some(band) = &s.band {
                let upper = band.iter().map(|&(x, _, hi)| (x, hi));
                let lower = band.iter().rev().map(|&(x, lo, _)| (x, lo));
                let outline: Vec<(f64, f64)> = upper.chain(lower).collect();
                chart
                    .draw_series(std::iter::once(Polygon::new(outline, colour.mix(0.2))))
                    .map_err(|e| e.to_string())?;
            }
            chart
                .draw_series(LineSeries::new(s.points.clone(), colour.stroke_width(2)))
                .map_err(|e| e.to_string())?;
            legend_area
                .draw(&PathElement::new(
                    [(0, legend_y), (24, legend_y)],
                    colour.stroke_width(2),
                ))
                .map_err(|e| e.to_string())?;
            for line in wrapped(&legend_area, &s.label, label_width)? {
                legend_area
                    .draw(&Text::new(line, (32, legend_y - 8), LEGEND_FONT))
                    .map_err(|e| e.to_string())?;
                legend_y += 18;
            }
            legend_y += 6;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    std::fs::rename(&temporary, path).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_legend_label_wraps_within_the_panel_and_keeps_every_word() {
        font().unwrap();
        let mut pixels = vec![0u8; 240 * 100 * 3];
        let area = BitMapBackend::with_buffer(&mut pixels, (240, 100)).into_drawing_area();
        let label = "CubeRotEnv (paper mode) (3 seeds, mean and one standard deviation)";
        let lines = wrapped(&area, label, 200).unwrap();
        assert!(lines.len() > 1, "{lines:?}");
        for line in &lines {
            let (width, _) = area
                .estimate_text_size(line, &LEGEND_FONT.into_text_style(&area))
                .unwrap();
            assert!(width <= 200, "{line:?} is {width} px wide");
        }
        assert_eq!(lines.join(" "), label);
        assert_eq!(wrapped(&area, "U'", 200).unwrap(), ["U'"]);
    }
}
