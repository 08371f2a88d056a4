//! What the post measures of a 5-axis program: the kinematic figures per feature and the
//! kinematic error plot (SVG).

use crate::gcode::comment_text;
use crate::tolerance::{AXIS_MAX_FLOOR, TICK_END_SLACK, TICK_STEP_FLOOR};
use toolpath::fixed;

/// Kinematic figures of one feature's print moves (paper Fig. 16).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct KinematicFigures {
    /// Largest distance (mm) from the planned path of the controller's interpolated positions,
    /// transformed back to the part.
    pub max_mm: f64,
    /// Mean of those distances (mm) over every interpolation step.
    pub mean_mm: f64,
    /// Planned print segments split into more than one move (for the C step or the error goal).
    pub subdivided_segments: usize,
    /// `G1` print moves written.
    pub print_moves: usize,
    /// Interpolation steps the figures are taken over.
    pub samples: usize,
    /// Planned points in the singularity cone, whose C was patched.
    pub singular_points: usize,
    /// Largest angle (degrees) between a planned tool axis and the one the bed gives at that
    /// point: 0 but for rounding outside the cone, at most the cone's half-angle inside it.
    pub max_axis_deviation_deg: f64,
    /// Largest C change (degrees) of one print move.
    pub max_c_step_deg: f64,
}

/// `s` escaped for XML text.
fn xml(s: &str) -> String {
    comment_text(s)
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A round tick step (1, 2 or 5 times a power of ten) giving about `count` ticks over `span`.
fn tick_step(span: f64, count: f64) -> f64 {
    let raw = (span / count).max(TICK_STEP_FLOOR);
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|k| k * p)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * p)
}

/// Colours of the features' lines, in turn.
const PALETTE: [&str; 8] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22",
];

/// Points kept in the plot at most; more are merged keeping each bin's largest error.
const PLOT_POINTS: usize = 4000;

/// The kinematic error along the printed path as SVG: x the length along the printed path
/// (mm), y the largest error of each print move (mm), one colour per feature, the goal dashed.
pub(super) fn error_plot(samples: &[(usize, f64, f64)], goal: f64, source: &str) -> String {
    let (w, h) = (900.0, 420.0);
    let (left, right, top, bottom) = (80.0, 160.0, 40.0, 60.0);
    let (pw, ph) = (w - left - right, h - top - bottom);
    let x_max = samples.last().map_or(0.0, |s| s.1).max(AXIS_MAX_FLOOR);
    let y_top = samples.iter().map(|s| s.2).fold(goal, f64::max) * 1.15;
    let sx = |x: f64| left + pw * x / x_max;
    let sy = |y: f64| top + ph * (1.0 - y / y_top);
    let mut o = String::new();
    o.push_str(&format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"12\">\n"
    ));
    o.push_str(&format!(
        "<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n"
    ));
    o.push_str(&format!(
        "<text x=\"{}\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">Kinematic error along the path: {}</text>\n",
        left + pw / 2.0,
        xml(source)
    ));
    // Axes, ticks and grid.
    o.push_str(&format!(
        "<path d=\"M{left} {top} V{} H{}\" stroke=\"black\" fill=\"none\"/>\n",
        top + ph,
        left + pw
    ));
    let xs = tick_step(x_max, 8.0);
    let mut x = 0.0;
    while x <= x_max * (1.0 + TICK_END_SLACK) {
        let px = sx(x);
        o.push_str(&format!(
            "<line x1=\"{px:.2}\" y1=\"{}\" x2=\"{px:.2}\" y2=\"{}\" stroke=\"black\"/><text x=\"{px:.2}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n",
            top + ph,
            top + ph + 5.0,
            top + ph + 18.0,
            tick_label(x, xs)
        ));
        x += xs;
    }
    let ys = tick_step(y_top, 6.0);
    let mut y = 0.0;
    while y <= y_top * (1.0 + TICK_END_SLACK) {
        let py = sy(y);
        o.push_str(&format!(
            "<line x1=\"{}\" y1=\"{py:.2}\" x2=\"{}\" y2=\"{py:.2}\" stroke=\"#dddddd\"/><text x=\"{}\" y=\"{:.2}\" text-anchor=\"end\">{}</text>\n",
            left,
            left + pw,
            left - 6.0,
            py + 4.0,
            tick_label(y, ys)
        ));
        y += ys;
    }
    o.push_str(&format!(
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">length along the printed path (mm)</text>\n",
        left + pw / 2.0,
        h - 15.0
    ));
    o.push_str(&format!(
        "<text x=\"20\" y=\"{}\" text-anchor=\"middle\" transform=\"rotate(-90 20 {})\">kinematic error (mm)</text>\n",
        top + ph / 2.0,
        top + ph / 2.0
    ));
    // One polyline per stretch of a feature, thinned to the plot's resolution.
    let bin = x_max / PLOT_POINTS as f64;
    let mut features: Vec<usize> = Vec::new();
    let mut i = 0;
    while i < samples.len() {
        let f = samples[i].0;
        let mut pts: Vec<(f64, f64)> = Vec::new();
        while i < samples.len() && samples[i].0 == f {
            let (_, x, y) = samples[i];
            match pts.last_mut() {
                Some(last)
                    if samples.len() > PLOT_POINTS
                        && (x / bin).floor() == (last.0 / bin).floor() =>
                {
                    if y > last.1 {
                        *last = (x, y);
                    }
                }
                _ => pts.push((x, y)),
            }
            i += 1;
        }
        let slot = features.iter().position(|&g| g == f).unwrap_or_else(|| {
            features.push(f);
            features.len() - 1
        });
        let colour = PALETTE[slot % PALETTE.len()];
        let d: Vec<String> = pts
            .iter()
            .map(|&(x, y)| format!("{:.2},{:.2}", sx(x), sy(y)))
            .collect();
        o.push_str(&format!(
            "<polyline class=\"feature-{f}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.2\" points=\"{}\"/>\n",
            d.join(" ")
        ));
    }
    // The goal.
    let gy = sy(goal);
    o.push_str(&format!(
        "<line class=\"goal\" x1=\"{left}\" y1=\"{gy:.2}\" x2=\"{}\" y2=\"{gy:.2}\" stroke=\"red\" stroke-dasharray=\"6 4\"/><text x=\"{}\" y=\"{:.2}\" fill=\"red\" text-anchor=\"end\">goal {} mm</text>\n",
        left + pw,
        left + pw - 4.0,
        gy - 4.0,
        fixed(goal, 3)
    ));
    // Legend.
    for (k, f) in features.iter().enumerate() {
        let ly = top + 30.0 + 18.0 * k as f64;
        o.push_str(&format!(
            "<line x1=\"{}\" y1=\"{ly:.2}\" x2=\"{}\" y2=\"{ly:.2}\" stroke=\"{}\" stroke-width=\"2\"/><text x=\"{}\" y=\"{:.2}\">feature {f}</text>\n",
            left + pw + 10.0,
            left + pw + 30.0,
            PALETTE[k % PALETTE.len()],
            left + pw + 36.0,
            ly + 4.0
        ));
    }
    o.push_str("</svg>\n");
    o
}

/// A tick value with as many decimals as its step needs.
fn tick_label(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    fixed(v, decimals)
}
