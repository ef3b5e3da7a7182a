//! `ncc plot FILE -o path.svg`: the toolpath as an SVG picture (or a PNG
//! image of it, `-o path.png`), in the XY
//! plane (ZX on a lathe), feed moves coloured by the speed the velocity
//! model gives them, rapid moves dashed, and the breaks of the path speed
//! marked; every move and mark carries its source line (`data-line`) and a
//! tooltip, so that a viewer can jump to the block. A move that a
//! macrocycle file or the cycle file makes also names that file
//! (`data-file`): its line is a line of that file. The moves are the tool
//! centre's, which the control moves and displays: under radius
//! compensation G41/G42 the programmed contour is a second layer above
//! them, thin and dotted. The picture is data only, without scripts or
//! styles; the editor's toolpath view adds those.
//!
//! A long run draws its first moves only ([`Sketch`]): a picture of
//! millions of moves is of no use to a browser, and would hold them all.
//!
//! A lathe's picture ([`Trace::diameter_axis`]) has a scale in program
//! units along both axes and one of two [`View`]s. Either is drawn to true
//! scale, so that tapers keep their angle and arcs stay round: the
//! diameter view, the default since the program's X words are diameters,
//! draws the part's whole profile, the path mirrored about the spindle
//! axis, and labels the X scale with diameters, so that a move to X50.
//! runs at the mark 50; the radius view draws the machined half and labels
//! radii. Stretching X to twice its scale instead would put X50. at 50 too,
//! but bend every taper and arc of the picture.

use std::fmt::Write as _;

use nc_exec::{
    run::{Axes, Motion, Path, Step, Trace},
    tool_path::tool_moves,
    velocity::{Break, Profile, TimingSink},
};

/// The picture's width in pixels; the height follows the toolpath.
const WIDTH: f64 = 1000.0;
const MARGIN: f64 = 20.0;
const LEGEND_HEIGHT: f64 = 70.0;
/// Slow to fast.
const PALETTE: [&str; 5] = ["#3b4cc0", "#6f9bf5", "#a9c66a", "#f4a259", "#d1342f"];
/// The programmed contour under radius compensation.
const PROGRAMMED_STYLE: &str = r##"stroke="#111" stroke-width="0.8" stroke-dasharray="1.5 2""##;

/// How a lathe's picture shows the diameter axis.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub(crate) enum View {
    /// The machined half profile, X labelled as a radius.
    Radius,
    /// The whole profile, mirrored about the spindle axis, X labelled as a
    /// diameter.
    #[default]
    Diameter,
}

/// The scale's tick labels, the centre line and the mirror image.
const SCALE_STYLE: &str = r##"fill="#666" font-size="10" stroke="white" stroke-width="3" paint-order="stroke""##;
const GRID_STYLE: &str = r##"stroke="#e4e4e4" stroke-width="0.6""##;
const CENTRE_LINE_STYLE: &str = r##"stroke="#555" stroke-width="0.8" stroke-dasharray="12 3 2 3""##;
const MIRROR_OPACITY: f64 = 0.35;

/// The moves a picture draws at most unless told otherwise: a browser
/// still shows this many, each with its tooltip.
pub(crate) const DEFAULT_MAX_MOVES: usize = 100_000;

/// What the picture keeps of a run as the velocity model times it: the
/// first moves with their profiles, and the breaks among them; of the
/// others only what the legend counts.
pub(crate) struct Sketch {
    max_moves: usize,
    pub steps: Vec<Step>,
    profiles: Vec<Profile>,
    breaks: Vec<Break>,
    /// Seconds, of the whole run.
    pub total_time: f64,
    /// The run's moves and breaks.
    pub moves: usize,
    break_count: usize,
}

impl Sketch {
    pub(crate) fn new(max_moves: usize) -> Sketch {
        Sketch {
            max_moves,
            steps: Vec::new(),
            profiles: Vec::new(),
            breaks: Vec::new(),
            total_time: 0.0,
            moves: 0,
            break_count: 0,
        }
    }

    /// The moves drawn, when not all of the run's.
    pub(crate) fn capped(&self) -> Option<usize> {
        (self.moves > self.profiles.len()).then_some(self.profiles.len())
    }
}

impl TimingSink for Sketch {
    fn speed_break(&mut self, _step: &Step, speed_break: Break) {
        self.break_count += 1;
        if speed_break.step < self.max_moves {
            self.breaks.push(speed_break);
        }
    }

    fn timed(&mut self, step: &Step, profile: Profile) {
        self.moves += 1;
        self.total_time += profile.duration;
        if self.profiles.len() < self.max_moves {
            self.steps.push(step.clone());
            self.profiles.push(profile);
        }
    }
}

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

/// A step as drawn, in program coordinates of the view plane: the tool
/// centre's path, and the programmed one where radius compensation moved
/// the tool off it.
struct Drawn {
    tool: Vec<(f64, f64)>,
    programmed: Option<Vec<(f64, f64)>>,
}

/// The SVG text of the run `sketch` kept, whose kept steps `trace` holds,
/// titled `title`; a lathe's in `view`.
pub(crate) fn svg(trace: &Trace, sketch: &Sketch, lines: &impl Lines, title: &str, view: View) -> String {
    let lathe_view = trace.diameter_axis.map(|_| view);
    let (across, up) = view_axes(trace);
    let slot = |letter: u8| trace.axes.iter().position(|&axis| axis == letter);
    let (Some(u), Some(v)) = (slot(across), slot(up)) else { return String::new() };
    let plane = |values: &Axes| (values[u], values[v]);
    let drawn: Vec<Drawn> = (0..trace.steps.len())
        .map(|index| {
            let step = &trace.steps[index];
            let centred = trace.centred(index);
            let start = trace.tool_start_of(index);
            let mut tool = vec![plane(&start)];
            let mut from = start;
            for tool_move in tool_moves(step, &start, centred.as_ref(), &trace.axes) {
                let piece = polyline(plane(&from), tool_move.path, plane(&tool_move.end), (across, up));
                tool.extend_from_slice(&piece[1..]);
                from = tool_move.end;
            }
            let programmed =
                centred.map(|_| polyline(plane(&trace.start_of(index)), step.path, plane(&step.end), (across, up)));
            Drawn { tool, programmed }
        })
        .collect();
    let points = drawn.iter().flat_map(|drawn| drawn.tool.iter().chain(drawn.programmed.iter().flatten()));
    let (mut min, mut max) = ((f64::INFINITY, f64::INFINITY), (f64::NEG_INFINITY, f64::NEG_INFINITY));
    for &(x, y) in points {
        min = (min.0.min(x), min.1.min(y));
        max = (max.0.max(x), max.1.max(y));
    }
    if !min.0.is_finite() {
        min = (0.0, 0.0);
        max = (1.0, 1.0);
    }
    if lathe_view == Some(View::Diameter) {
        let reach = min.1.abs().max(max.1.abs());
        (min.1, max.1) = (-reach, reach);
    }
    let span = (max.0 - min.0).max(max.1 - min.1).max(1e-3);
    let scale = (WIDTH - 2.0 * MARGIN) / span;
    let height = (max.1 - min.1) * scale + 2.0 * MARGIN;
    let pixel = |(x, y): (f64, f64)| (MARGIN + (x - min.0) * scale, MARGIN + (max.1 - y) * scale);
    let d = |polyline: &[(f64, f64)]| {
        let mut d = String::new();
        for (i, &point) in polyline.iter().enumerate() {
            let (x, y) = pixel(point);
            let _ = write!(d, "{}{x:.2} {y:.2}", if i == 0 { "M" } else { " L" });
        }
        d
    };
    let drawable = |index: usize| matches!(trace.steps[index].motion, Motion::Rapid | Motion::Feed);
    // The colours span the feed moves; rapids are drawn apart.
    let feed_peaks = trace.steps.iter().zip(&sketch.profiles).filter(|(step, _)| step.motion == Motion::Feed);
    let fastest = feed_peaks.map(|(_, profile)| profile.peak).fold(0.0, f64::max).max(1.0);

    let mut out = String::new();
    let legend_height = LEGEND_HEIGHT + if sketch.capped().is_some() { 22.0 } else { 0.0 };
    let total_height = height + legend_height;
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{total_height:.0}" viewBox="0 0 {WIDTH} {total_height:.0}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(out, "<title>{}</title>", escape(title));
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    // Written over the drawing, so that no move hides them.
    let mut scale_labels = String::new();
    if let Some(view) = lathe_view {
        let axis_y = pixel((0.0, 0.0)).1;
        scale_labels = lathe_scale(&mut out, view, (min, max), &pixel, axis_y);
        if view == View::Diameter {
            // The other half of the profile, as the same layers reflected.
            let _ = writeln!(
                out,
                r##"<g id="mirror-image" transform="matrix(1 0 0 -1 0 {:.2})" opacity="{MIRROR_OPACITY}"><use href="#tool-centre"/><use href="#programmed-contour"/></g>"##,
                2.0 * axis_y
            );
        }
    }
    let _ = writeln!(out, r#"<g id="tool-centre">"#);
    for (index, drawn) in drawn.iter().enumerate() {
        if drawn.tool.len() < 2 || !drawable(index) {
            continue;
        }
        let step = &trace.steps[index];
        let profile = sketch.profiles[index];
        let style = match step.motion {
            Motion::Rapid => r##"stroke="#888" stroke-dasharray="4 3""##.to_owned(),
            _ => format!(r#"stroke="{}""#, colour(profile.peak, fastest)),
        };
        let line = lines.line_of(index);
        let source = source_attributes(lines, index);
        let _ = writeln!(
            out,
            r#"<path{source} d="{}" fill="none" {style} stroke-width="1.5"><title>line {line}: {:.0} mm/min, {:.3} s</title></path>"#,
            d(&drawn.tool),
            profile.peak,
            profile.duration
        );
    }
    let _ = writeln!(out, "</g>");
    let mut compensated = false;
    let _ = writeln!(out, r#"<g id="programmed-contour">"#);
    for (index, drawn) in drawn.iter().enumerate() {
        let Some(programmed) = drawn.programmed.as_ref().filter(|polyline| polyline.len() >= 2 && drawable(index))
        else {
            continue;
        };
        compensated = true;
        let line = lines.line_of(index);
        let source = source_attributes(lines, index);
        let _ = writeln!(
            out,
            r#"<path{source} d="{}" fill="none" {PROGRAMMED_STYLE}><title>line {line}: the programmed contour; the tool centre runs beside it (G41/G42)</title></path>"#,
            d(programmed)
        );
    }
    let _ = writeln!(out, "</g>");
    for speed_break in &sketch.breaks {
        let tool = drawn.get(speed_break.step).map(|drawn| &drawn.tool);
        let place =
            if speed_break.at_start() { tool.and_then(|tool| tool.first()) } else { tool.and_then(|tool| tool.last()) };
        let Some(&place) = place else { continue };
        let (x, y) = pixel(place);
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
    out.push_str(&scale_labels);
    legend(&mut out, height, fastest, sketch, (across, up), compensated, lathe_view);
    out.push_str("</svg>\n");
    out
}

/// The lathe's scale: grid lines at round steps in program units, and the
/// spindle axis as a centre line where it is in the picture, under the
/// drawing; the lines' values, X as `view` labels it, to write over it.
fn lathe_scale(
    out: &mut String,
    view: View,
    (min, max): ((f64, f64), (f64, f64)),
    pixel: &impl Fn((f64, f64)) -> (f64, f64),
    axis_y: f64,
) -> String {
    let (left, top) = pixel((min.0, max.1));
    let (right, bottom) = pixel((max.0, min.1));
    let mut labels = format!("<g id=\"scale\" {SCALE_STYLE}>\n");
    let _ = writeln!(out, r#"<g id="grid" {GRID_STYLE}>"#);
    for (value, label) in ticks(min.0, max.0) {
        let x = pixel((value, 0.0)).0;
        let _ = writeln!(out, r#"<line x1="{x:.2}" y1="{top:.2}" x2="{x:.2}" y2="{bottom:.2}"/>"#);
        let _ = writeln!(labels, r#"<text x="{:.2}" y="{:.2}">{label}</text>"#, x + 2.0, bottom + 12.0);
    }
    let marks = match view {
        View::Radius => ticks(min.1, max.1),
        // Round diameters, on both halves of the profile alike.
        View::Diameter => ticks(0.0, 2.0 * max.1)
            .into_iter()
            .flat_map(|(diameter, label)| {
                let mirrored = (diameter > 0.0).then(|| (-diameter / 2.0, label.clone()));
                [(diameter / 2.0, label)].into_iter().chain(mirrored)
            })
            .collect(),
    };
    for (value, label) in marks {
        let y = pixel((0.0, value)).1;
        let _ = writeln!(out, r#"<line x1="{left:.2}" y1="{y:.2}" x2="{right:.2}" y2="{y:.2}"/>"#);
        let _ = writeln!(labels, r#"<text x="{:.2}" y="{:.2}">{label}</text>"#, left + 2.0, y - 2.0);
    }
    let _ = writeln!(out, "</g>");
    labels.push_str("</g>\n");
    if (top - 0.01..=bottom + 0.01).contains(&axis_y) {
        let _ = writeln!(
            out,
            r#"<line id="spindle-axis" x1="{left:.2}" y1="{axis_y:.2}" x2="{right:.2}" y2="{axis_y:.2}" {CENTRE_LINE_STYLE}/>"#
        );
    }
    labels
}

/// The round values from `low` to `high`, about eight of them, each with
/// its label.
fn ticks(low: f64, high: f64) -> Vec<(f64, String)> {
    let step = tick_step(low, high);
    let places = (-step.log10().floor()).max(0.0) as usize;
    let first = (low / step - 1e-9).ceil() as i64;
    let last = (high / step + 1e-9).floor() as i64;
    (first..=last)
        .map(|i| {
            let value = i as f64 * step;
            // Adding zero makes -0 print as 0.
            (value, format!("{:.places$}", value + 0.0))
        })
        .collect()
}

/// 1, 2 or 5 times a power of ten, for about eight ticks over the span.
fn tick_step(low: f64, high: f64) -> f64 {
    let rough = ((high - low) / 8.0).max(1e-3);
    let power = 10f64.powf(rough.log10().floor());
    [1.0, 2.0, 5.0, 10.0].into_iter().map(|factor| factor * power).find(|&step| step >= rough).unwrap_or(10.0 * power)
}

/// The plane of the picture: ZX on a lathe (the diameter axis up), else
/// the machine's first two axes.
fn view_axes(trace: &Trace) -> (u8, u8) {
    match trace.diameter_axis {
        Some(diameter) => (trace.axes.iter().copied().find(|&axis| axis != diameter).unwrap_or(b'Z'), diameter),
        None => (trace.axes.first().copied().unwrap_or(b'X'), trace.axes.get(1).copied().unwrap_or(b'Y')),
    }
}

/// A move from `from` along `path` to `to` in the view plane of the axes
/// `letters`; an arc in that plane as chords of at most 5°.
fn polyline(from: (f64, f64), path: Path, to: (f64, f64), letters: (u8, u8)) -> Vec<(f64, f64)> {
    let Path::Arc { plane, centre, clockwise } = path else { return vec![from, to] };
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

fn legend(
    out: &mut String,
    top: f64,
    fastest: f64,
    sketch: &Sketch,
    (across, up): (u8, u8),
    compensated: bool,
    lathe_view: Option<View>,
) {
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
    let mut x = MARGIN + 260.0;
    if compensated {
        let _ = writeln!(out, r#"<line x1="{x}" y1="{0}" x2="{1}" y2="{0}" {PROGRAMMED_STYLE}/>"#, y2 - 4.0, x + 24.0);
        let _ = writeln!(out, r#"<text x="{}" y="{y2}">programmed contour (G41/G42)</text>"#, x + 30.0);
        x += 220.0;
    }
    let view = match lathe_view {
        Some(View::Radius) => format!(", {} as a radius", char::from(up)),
        Some(View::Diameter) => format!(", {} as a diameter", char::from(up)),
        None => String::new(),
    };
    let _ = writeln!(
        out,
        r#"<text x="{x}" y="{y2}">{}{} plane{view} · total time {} · {} breaks</text>"#,
        char::from(across),
        char::from(up),
        ncc_analysis::clock(sketch.total_time),
        sketch.break_count
    );
    if let Some(drawn) = sketch.capped() {
        let _ = writeln!(
            out,
            r##"<text x="{MARGIN}" y="{}" fill="#d1342f" font-weight="bold">{}</text>"##,
            y2 + 22.0,
            escape(&capped_note(drawn, sketch.moves))
        );
    }
}

/// How many pixels a PNG has per unit of the SVG: twice, so that thin
/// lines and labels stay sharp in a report.
const PNG_SCALE: f32 = 2.0;

/// The picture `svg` as a PNG image on white, its labels in a sans-serif
/// font of the system's.
pub(crate) fn png(svg: &str) -> Result<Vec<u8>, String> {
    use resvg::{tiny_skia, usvg};
    let mut options = usvg::Options::default();
    let fonts = options.fontdb_mut();
    fonts.load_system_fonts();
    // fontdb takes Arial for sans-serif, which a Linux machine rarely has:
    // the first sans-serif family installed stands in.
    let sans = fonts
        .faces()
        .flat_map(|face| &face.families)
        .map(|(family, _)| family.clone())
        .find(|family| family.contains("Sans") && !family.contains("Mono") && !family.contains("Serif"));
    if let Some(sans) = sans {
        fonts.set_sans_serif_family(sans.clone());
        options.font_family = sans;
    }
    let tree = usvg::Tree::from_str(svg, &options).map_err(|error| error.to_string())?;
    let size = tree.size().to_int_size().scale_by(PNG_SCALE).ok_or("the picture has no size")?;
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height()).ok_or("the picture is too large")?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(&tree, tiny_skia::Transform::from_scale(PNG_SCALE, PNG_SCALE), &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|error| error.to_string())
}

/// What a picture that draws only the first `drawn` of a run's `moves`
/// says about it.
pub(crate) fn capped_note(drawn: usize, moves: usize) -> String {
    format!("drawn: the first {drawn} of the run's {moves} moves; the total time and the breaks are the whole run's")
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}
