//! `ncc plot FILE -o path.svg`: the toolpath as an SVG picture, in the XY
//! plane (ZX on a lathe), feed moves coloured by the speed the velocity
//! model gives them, rapid moves dashed, and the breaks of the path speed
//! marked; every move and mark carries its source line (`data-line`) and a
//! tooltip, so that a viewer can jump to the block. A move that a
//! macrocycle file or the cycle file makes also names that file
//! (`data-file`): its line is a line of that file. The picture is data
//! only, without scripts or styles; the editor's toolpath view adds those.

use std::fmt::Write as _;

use nc_exec::{
    run::{Axes, Motion, Path, Trace},
    velocity::Timing,
};

/// The picture's width in pixels; the height follows the toolpath.
const WIDTH: f64 = 1000.0;
const MARGIN: f64 = 20.0;
const LEGEND_HEIGHT: f64 = 70.0;
/// Slow to fast.
const PALETTE: [&str; 5] = ["#3b4cc0", "#6f9bf5", "#a9c66a", "#f4a259", "#d1342f"];

/// Where a step's line is, for the marks' `data-line` and `data-file`.
pub(crate) trait Lines {
    /// The line, counted from 1, in the step's file.
    fn line_of(&self, step: usize) -> u32;
    /// The step's file when it is not the program itself.
    fn file_of(&self, step: usize) -> Option<&str>;
}

/// ` data-line="…"`, and ` data-file="…"` outside the program.
fn source_attributes(lines: &impl Lines, step: usize) -> String {
    let line = lines.line_of(step);
    match lines.file_of(step) {
        Some(file) => format!(r#" data-line="{line}" data-file="{}""#, escape(file)),
        None => format!(r#" data-line="{line}""#),
    }
}

/// The SVG text of `trace` timed by `timing`, titled `title`.
pub(crate) fn svg(trace: &Trace, timing: &Timing, lines: &impl Lines, title: &str) -> String {
    let (across, up) = view_axes(trace);
    let slot = |letter: u8| trace.axes.iter().position(|&axis| axis == letter);
    let (Some(u), Some(v)) = (slot(across), slot(up)) else { return String::new() };
    // Every move as a polyline in program coordinates of the view plane.
    let moves: Vec<Vec<(f64, f64)>> =
        (0..trace.steps.len()).map(|index| polyline(trace, index, (across, up), (u, v))).collect();
    let points = moves.iter().flatten();
    let (mut min, mut max) = ((f64::INFINITY, f64::INFINITY), (f64::NEG_INFINITY, f64::NEG_INFINITY));
    for &(x, y) in points {
        min = (min.0.min(x), min.1.min(y));
        max = (max.0.max(x), max.1.max(y));
    }
    if !min.0.is_finite() {
        min = (0.0, 0.0);
        max = (1.0, 1.0);
    }
    let span = (max.0 - min.0).max(max.1 - min.1).max(1e-3);
    let scale = (WIDTH - 2.0 * MARGIN) / span;
    let height = (max.1 - min.1) * scale + 2.0 * MARGIN;
    let pixel = |(x, y): (f64, f64)| (MARGIN + (x - min.0) * scale, MARGIN + (max.1 - y) * scale);
    // The colours span the feed moves; rapids are drawn apart.
    let feed_peaks = trace.steps.iter().zip(&timing.profiles).filter(|(step, _)| step.motion == Motion::Feed);
    let fastest = feed_peaks.map(|(_, profile)| profile.peak).fold(0.0, f64::max).max(1.0);

    let mut out = String::new();
    let total_height = height + LEGEND_HEIGHT;
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{total_height:.0}" viewBox="0 0 {WIDTH} {total_height:.0}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(out, "<title>{}</title>", escape(title));
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for (index, polyline) in moves.iter().enumerate() {
        let step = &trace.steps[index];
        if polyline.len() < 2 || !matches!(step.motion, Motion::Rapid | Motion::Feed) {
            continue;
        }
        let profile = timing.profiles.get(index).copied().unwrap_or_default();
        let style = match step.motion {
            Motion::Rapid => r##"stroke="#888" stroke-dasharray="4 3""##.to_owned(),
            _ => format!(r#"stroke="{}""#, colour(profile.peak, fastest)),
        };
        let mut d = String::new();
        for (i, &point) in polyline.iter().enumerate() {
            let (x, y) = pixel(point);
            let _ = write!(d, "{}{x:.2} {y:.2}", if i == 0 { "M" } else { " L" });
        }
        let line = lines.line_of(index);
        let source = source_attributes(lines, index);
        let _ = writeln!(
            out,
            r#"<path{source} d="{d}" fill="none" {style} stroke-width="1.5"><title>line {line}: {:.0} mm/min, {:.3} s</title></path>"#,
            profile.peak, profile.duration
        );
    }
    for speed_break in &timing.breaks {
        let Some(&end) = moves[speed_break.step].last() else { continue };
        let (x, y) = pixel(end);
        let fill = if speed_break.at == 0.0 { "#d1342f" } else { "#f4a259" };
        let line = lines.line_of(speed_break.step);
        let source = source_attributes(lines, speed_break.step);
        let _ = writeln!(
            out,
            r#"<circle{source} cx="{x:.2}" cy="{y:.2}" r="3" fill="{fill}"><title>line {line}: {}: {:.0} → {:.0} mm/min, {:.3} s lost</title></circle>"#,
            escape(&speed_break.reason.to_string()),
            speed_break.before,
            speed_break.at,
            speed_break.lost
        );
    }
    legend(&mut out, height, fastest, timing, (across, up));
    out.push_str("</svg>\n");
    out
}

/// The plane of the picture: ZX on a lathe (the diameter axis up), else
/// the machine's first two axes.
fn view_axes(trace: &Trace) -> (u8, u8) {
    match trace.diameter_axis {
        Some(diameter) => (trace.axes.iter().copied().find(|&axis| axis != diameter).unwrap_or(b'Z'), diameter),
        None => (trace.axes.first().copied().unwrap_or(b'X'), trace.axes.get(1).copied().unwrap_or(b'Y')),
    }
}

/// Step `index` from its start to its end in the view plane; an arc in that
/// plane as chords of at most 5°.
fn polyline(trace: &Trace, index: usize, letters: (u8, u8), (u, v): (usize, usize)) -> Vec<(f64, f64)> {
    let step = &trace.steps[index];
    let start: Axes = trace.start_of(index);
    let (from, to) = ((start[u], start[v]), (step.end[u], step.end[v]));
    let Path::Arc { plane, centre, clockwise } = step.path else { return vec![from, to] };
    let centre = if plane == letters {
        (centre[0], centre[1])
    } else if plane == (letters.1, letters.0) {
        (centre[1], centre[0])
    } else {
        return vec![from, to];
    };
    // Seen with the axes swapped, the arc turns the other way.
    let clockwise = clockwise == (plane == letters);
    let radius = (from.0 - centre.0).hypot(from.1 - centre.1);
    let angle_of = |(x, y): (f64, f64)| (y - centre.1).atan2(x - centre.0);
    let (a0, a1) = (angle_of(from), angle_of(to));
    let tau = std::f64::consts::TAU;
    let mut sweep = if clockwise { a0 - a1 } else { a1 - a0 };
    if sweep <= 1e-12 {
        sweep += tau;
    }
    let pieces = (sweep / 5f64.to_radians()).ceil().max(1.0) as usize;
    let sign = if clockwise { -1.0 } else { 1.0 };
    (0..=pieces)
        .map(|i| {
            let angle = a0 + sign * sweep * i as f64 / pieces as f64;
            (centre.0 + radius * angle.cos(), centre.1 + radius * angle.sin())
        })
        .collect()
}

fn colour(speed: f64, fastest: f64) -> &'static str {
    let bucket = ((speed / fastest) * PALETTE.len() as f64).floor() as usize;
    PALETTE[bucket.min(PALETTE.len() - 1)]
}

fn legend(out: &mut String, top: f64, fastest: f64, timing: &Timing, (across, up): (u8, u8)) {
    let y = top + 20.0;
    let buckets = PALETTE.len() as f64;
    for (i, colour) in PALETTE.iter().enumerate() {
        let x = MARGIN + i as f64 * 150.0;
        let (low, high) = (fastest * i as f64 / buckets, fastest * (i + 1) as f64 / buckets);
        let _ = writeln!(out, r#"<rect x="{x}" y="{}" width="14" height="10" fill="{colour}"/>"#, y - 9.0);
        let _ = writeln!(out, r#"<text x="{}" y="{y}">{low:.0}–{high:.0} mm/min</text>"#, x + 18.0);
    }
    let y2 = y + 22.0;
    let _ = writeln!(
        out,
        r##"<line x1="{MARGIN}" y1="{0}" x2="{1}" y2="{0}" stroke="#888" stroke-dasharray="4 3"/>"##,
        y2 - 4.0,
        MARGIN + 24.0
    );
    let _ = writeln!(out, r#"<text x="{}" y="{y2}">rapid</text>"#, MARGIN + 30.0);
    let _ = writeln!(out, r##"<circle cx="{}" cy="{}" r="3" fill="#d1342f"/>"##, MARGIN + 100.0, y2 - 4.0);
    let _ = writeln!(out, r#"<text x="{}" y="{y2}">stop</text>"#, MARGIN + 108.0);
    let _ = writeln!(out, r##"<circle cx="{}" cy="{}" r="3" fill="#f4a259"/>"##, MARGIN + 160.0, y2 - 4.0);
    let _ = writeln!(out, r#"<text x="{}" y="{y2}">slow-down</text>"#, MARGIN + 168.0);
    let _ = writeln!(
        out,
        r#"<text x="{}" y="{y2}">{}{} plane · total time {} · {} breaks</text>"#,
        MARGIN + 260.0,
        char::from(across),
        char::from(up),
        ncc_analysis::clock(timing.total_time()),
        timing.breaks.len()
    );
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}
