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
const LEGEND_HEIGHT: f64 = 92.0;
/// Slow to fast.
const PALETTE: [&str; 5] = ["#3b4cc0", "#6f9bf5", "#a9c66a", "#f4a259", "#d1342f"];
/// The programmed contour under radius compensation.
const PROGRAMMED_STYLE: &str = r##"stroke="#111" stroke-width="0.8" stroke-dasharray="1.5 2""##;

/// How a picture shows the program: a lathe's diameter axis, or a mill's
/// three axes. A lathe takes its views only, a mill its own: either's
/// default, [`View::Diameter`], is the plane view on a mill.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub(crate) enum View {
    /// A lathe's machined half profile, X labelled as a radius.
    Radius,
    /// A lathe's whole profile, mirrored about the spindle axis, X labelled
    /// as a diameter.
    #[default]
    Diameter,
    /// A mill's view plane seen from the tool axis.
    Top,
    /// A mill's three axes in an isometric view.
    Iso,
}

impl View {
    /// The view a picture of `trace` asked for in `self` is drawn in.
    pub(crate) fn drawn(self, trace: &Trace) -> View {
        match (trace.diameter_axis.is_some(), self) {
            (true, View::Radius) => View::Radius,
            (true, _) => View::Diameter,
            (false, View::Iso) => View::Iso,
            (false, _) => View::Top,
        }
    }

    /// Whether the view is a lathe's.
    fn is_lathe(self) -> bool {
        matches!(self, View::Radius | View::Diameter)
    }

    /// Where a point of the program lands in the view's plane: the view
    /// plane seen from the tool axis, or in the isometric view the three
    /// axes seen from above their first octant, the plane's axes at 30°
    /// below the horizontal, the tool axis up.
    fn project(self, [u, v, w]: Point) -> (f64, f64) {
        match self {
            View::Iso => {
                let (cos, sin) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
                ((u - v) * cos, (u + v) * sin + w)
            }
            View::Radius | View::Diameter | View::Top => (u, v),
        }
    }
}

/// The scale's tick labels, the centre line and the mirror image.
const SCALE_STYLE: &str = r##"fill="#666" font-size="10" stroke="white" stroke-width="3" paint-order="stroke""##;
const GRID_STYLE: &str = r##"stroke="#e4e4e4" stroke-width="0.6""##;
const EXTENT_STYLE: &str = r##"stroke="#b0b0b0" stroke-width="0.8" stroke-dasharray="4 3""##;
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

/// A step as drawn, in program coordinates: the tool centre's path, and
/// the programmed one where radius compensation moved the tool off it;
/// each point is the view plane's two axes and the tool axis.
struct Drawn {
    tool: Vec<Point>,
    programmed: Option<Vec<Point>>,
}

/// A point in program coordinates: across and up in the view plane, and
/// along the tool axis (0 on a machine without one).
type Point = [f64; 3];

/// The picture's frame: what it shows of the program's plane, and how a
/// point of it lands on the picture.
struct Frame {
    min: (f64, f64),
    max: (f64, f64),
    scale: f64,
    height: f64,
}

impl Frame {
    /// The run stayed at one point: there is no scale to draw.
    fn is_point(&self) -> bool {
        (self.max.0 - self.min.0).max(self.max.1 - self.min.1) <= 1e-6
    }

    fn pixel(&self, (x, y): (f64, f64)) -> (f64, f64) {
        (MARGIN + (x - self.min.0) * self.scale, MARGIN + (self.max.1 - y) * self.scale)
    }
}

/// The SVG text of the run `sketch` kept, whose kept steps `trace` holds,
/// titled `title`, in `view`.
pub(crate) fn svg(trace: &Trace, sketch: &Sketch, lines: &impl Lines, title: &str, view: View) -> String {
    let view = view.drawn(trace);
    let (across, up) = view_axes(trace);
    let slot = |letter: u8| trace.axes.iter().position(|&axis| axis == letter);
    let (Some(u), Some(v)) = (slot(across), slot(up)) else { return String::new() };
    let tool_axis = (trace.diameter_axis.is_none()).then(|| trace.axes.get(2).copied()).flatten();
    let w = tool_axis.and_then(slot);
    let point = |values: &Axes| [values[u], values[v], w.map_or(0.0, |w| values[w])];
    let drawn: Vec<Drawn> = (0..trace.steps.len())
        .map(|index| {
            let step = &trace.steps[index];
            let centred = trace.centred(index);
            let start = trace.tool_start_of(index);
            let mut tool = vec![point(&start)];
            let mut from = start;
            for tool_move in tool_moves(step, &start, centred.as_ref(), &trace.axes) {
                let piece = path_points(point(&from), tool_move.path, point(&tool_move.end), (across, up));
                tool.extend_from_slice(&piece[1..]);
                from = tool_move.end;
            }
            let programmed =
                centred.map(|_| path_points(point(&trace.start_of(index)), step.path, point(&step.end), (across, up)));
            Drawn { tool, programmed }
        })
        .collect();
    let extent = part_extent(trace, &drawn);
    let frame = frame(trace, &drawn, extent, view);
    let pixel = |point: Point| frame.pixel(view.project(point));
    let d = |polyline: &[Point]| {
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
    let total_height = frame.height + legend_height;
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{total_height:.0}" viewBox="0 0 {WIDTH} {total_height:.0}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(out, "<title>{}</title>", escape(title));
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    // Moves outside the frame (the first rapid from the machine's home)
    // are cut at its edge.
    let _ = writeln!(
        out,
        r#"<clipPath id="frame"><rect x="0" y="0" width="{WIDTH}" height="{:.2}"/></clipPath>"#,
        frame.height
    );
    // Written over the drawing, so that no move hides them.
    let scale_labels = match view {
        _ if frame.is_point() => String::new(),
        View::Iso => isometric_scale(&mut out, &frame, extent, (across, up, tool_axis)),
        View::Radius | View::Diameter | View::Top => plane_scale(&mut out, &frame, view, (across, up)),
    };
    // Where program coordinates land, for a viewer that shows them (a
    // plane view): x = left + (X − min-x) · scale, y = top + (max-y − Y) ·
    // scale.
    let _ = writeln!(
        out,
        r#"<g id="drawing" clip-path="url(#frame)" data-projection="{}" data-min-x="{:.6}" data-max-y="{:.6}" data-scale="{:.6}" data-left="{MARGIN}" data-top="{MARGIN}">"#,
        if view == View::Iso { "isometric" } else { "plane" },
        frame.min.0,
        frame.max.1,
        frame.scale
    );
    if view == View::Diameter {
        // The other half of the profile, as the same layers reflected.
        let _ = writeln!(
            out,
            r##"<g id="mirror-image" transform="matrix(1 0 0 -1 0 {:.2})" opacity="{MIRROR_OPACITY}"><use href="#tool-centre"/><use href="#programmed-contour"/></g>"##,
            2.0 * frame.pixel((0.0, 0.0)).1
        );
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
    let _ = writeln!(out, "</g>");
    out.push_str(&scale_labels);
    let shown = Shown { axes: (across, up, tool_axis), compensated, view, extent };
    legend(&mut out, frame.height, fastest, sketch, &shown);
    out.push_str("</svg>\n");
    out
}

/// What the legend says of the picture besides the speeds.
struct Shown {
    /// The view plane's axes and the tool axis.
    axes: (u8, u8, Option<u8>),
    compensated: bool,
    view: View,
    extent: Option<(Point, Point)>,
}

/// The part's extent: the smallest box around every cutting move of the
/// tool centre, in program coordinates; `None` without one.
fn part_extent(trace: &Trace, drawn: &[Drawn]) -> Option<(Point, Point)> {
    let cutting = drawn.iter().enumerate().filter(|(index, _)| trace.steps[*index].motion == Motion::Feed);
    let points = cutting.flat_map(|(_, drawn)| drawn.tool.iter().chain(drawn.programmed.iter().flatten()));
    points.fold(None, |extent, &point| {
        let (low, high) = extent.unwrap_or((point, point));
        Some((std::array::from_fn(|i| low[i].min(point[i])), std::array::from_fn(|i| high[i].max(point[i]))))
    })
}

/// The frame that fits the part (the cutting moves, with a margin) in
/// `view`: rapids that go further, the first from the machine's
/// home above all, would shrink the part to a corner. A run without a
/// cutting move is fitted to all its moves.
fn frame(trace: &Trace, drawn: &[Drawn], extent: Option<(Point, Point)>, view: View) -> Frame {
    let corners = |(low, high): (Point, Point)| -> Vec<Point> {
        (0..8).map(|i| std::array::from_fn(|axis| if i >> axis & 1 == 0 { low[axis] } else { high[axis] })).collect()
    };
    let fitted: Vec<Point> = match extent {
        Some(extent) => corners(extent),
        None => drawn
            .iter()
            .enumerate()
            .filter(|(index, _)| trace.steps[*index].motion != Motion::Dwell)
            .flat_map(|(_, drawn)| drawn.tool.iter().chain(drawn.programmed.iter().flatten()).copied())
            .collect(),
    };
    let (mut min, mut max) = ((f64::INFINITY, f64::INFINITY), (f64::NEG_INFINITY, f64::NEG_INFINITY));
    for point in fitted {
        let (x, y) = view.project(point);
        min = (min.0.min(x), min.1.min(y));
        max = (max.0.max(x), max.1.max(y));
    }
    if !min.0.is_finite() {
        (min, max) = ((0.0, 0.0), (1.0, 1.0));
    }
    if view.is_lathe() {
        // A lathe's part turns about the spindle axis: it stays in view.
        (min.1, max.1) = (min.1.min(0.0), max.1.max(0.0));
    }
    // A margin around the part; a run that stays at one point has none
    // to show.
    let size = (max.0 - min.0).max(max.1 - min.1);
    let pad = if size > 1e-6 { 0.05 * size.max(1.0) } else { 0.0 };
    (min, max) = ((min.0 - pad, min.1 - pad), (max.0 + pad, max.1 + pad));
    if view == View::Diameter {
        let reach = min.1.abs().max(max.1.abs());
        (min.1, max.1) = (-reach, reach);
    }
    let span = (max.0 - min.0).max(max.1 - min.1).max(1e-3);
    let scale = (WIDTH - 2.0 * MARGIN) / span;
    let height = (max.1 - min.1) * scale + 2.0 * MARGIN;
    Frame { min, max, scale, height }
}

/// The scale of a plane view: grid lines at round steps in mm, labelled
/// along the bottom and the left edge, with the axes' names, under the
/// drawing; the labels, to write over it. A lathe labels its diameter
/// axis as `view` shows it, and draws the spindle axis as a centre line.
fn plane_scale(out: &mut String, frame: &Frame, view: View, (across, up): (u8, u8)) -> String {
    let (min, max) = (frame.min, frame.max);
    let (left, top) = frame.pixel((min.0, max.1));
    let (right, bottom) = frame.pixel((max.0, min.1));
    let mut labels = format!("<g id=\"scale\" {SCALE_STYLE}>\n");
    let _ = writeln!(out, r#"<g id="grid" {GRID_STYLE}>"#);
    for (value, label) in ticks(min.0, max.0) {
        let x = frame.pixel((value, 0.0)).0;
        line(out, (x, top), (x, bottom));
        let _ = writeln!(labels, r#"<text x="{:.2}" y="{:.2}">{label}</text>"#, x + 2.0, bottom - 4.0);
    }
    let marks = match view {
        // Round diameters, on both halves of the profile alike.
        View::Diameter => ticks(0.0, 2.0 * max.1)
            .into_iter()
            .flat_map(|(diameter, label)| {
                let mirrored = (diameter > 0.0).then(|| (-diameter / 2.0, label.clone()));
                [(diameter / 2.0, label)].into_iter().chain(mirrored)
            })
            .collect(),
        _ => ticks(min.1, max.1),
    };
    for (value, label) in marks {
        let y = frame.pixel((0.0, value)).1;
        line(out, (left, y), (right, y));
        let _ = writeln!(labels, r#"<text x="{:.2}" y="{:.2}">{label}</text>"#, left + 2.0, y - 2.0);
    }
    let _ = writeln!(out, "</g>");
    let up_name = match view {
        View::Diameter => format!("{} (diameter)", char::from(up)),
        View::Radius => format!("{} (radius)", char::from(up)),
        View::Top | View::Iso => char::from(up).to_string(),
    };
    let _ = writeln!(
        labels,
        r#"<text x="{:.2}" y="{:.2}" text-anchor="end" font-weight="bold">{} mm</text>"#,
        right - 4.0,
        bottom - 16.0,
        char::from(across)
    );
    // Beside the top tick's label, not on it.
    let _ = writeln!(
        labels,
        r#"<text x="{:.2}" y="{:.2}" font-weight="bold">{up_name} mm</text>"#,
        left + 36.0,
        top + 12.0
    );
    labels.push_str("</g>\n");
    let axis_y = frame.pixel((0.0, 0.0)).1;
    if view.is_lathe() && (top - 0.01..=bottom + 0.01).contains(&axis_y) {
        let _ = writeln!(
            out,
            r#"<line id="spindle-axis" x1="{left:.2}" y1="{axis_y:.2}" x2="{right:.2}" y2="{axis_y:.2}" {CENTRE_LINE_STYLE}/>"#
        );
    }
    labels
}

/// The scale of the isometric view: a grid at round steps in mm on the
/// plane at the part's bottom, labelled along two of its edges, and the
/// three axes' directions; the labels, to write over the drawing.
fn isometric_scale(
    out: &mut String,
    frame: &Frame,
    extent: Option<(Point, Point)>,
    (across, up, tool_axis): (u8, u8, Option<u8>),
) -> String {
    let mut labels = format!("<g id=\"scale\" {SCALE_STYLE}>\n");
    let pixel = |point: Point| frame.pixel(View::Iso.project(point));
    if let Some((low, high)) = extent {
        let _ = writeln!(out, r#"<g id="grid" {GRID_STYLE}>"#);
        let (u_ticks, v_ticks) = (ticks(low[0], high[0]), ticks(low[1], high[1]));
        let floor = low[2];
        for (value, label) in &u_ticks {
            let (a, b) = (pixel([*value, low[1], floor]), pixel([*value, high[1], floor]));
            line(out, a, b);
            // Starting right of the line and the Y labels ending left of
            // theirs keeps the two apart at the front corner they share.
            let _ = writeln!(labels, r#"<text x="{:.2}" y="{:.2}">{label}</text>"#, a.0 + 2.0, a.1 + 14.0);
        }
        for (value, label) in &v_ticks {
            let (a, b) = (pixel([low[0], *value, floor]), pixel([high[0], *value, floor]));
            line(out, a, b);
            let _ = writeln!(
                labels,
                r#"<text x="{:.2}" y="{:.2}" text-anchor="end">{label}</text>"#,
                a.0 - 4.0,
                a.1 + 12.0
            );
        }
        let _ = writeln!(out, "</g>");
        if high[2] > low[2] {
            extent_box(out, &mut labels, &pixel, (low, high));
        }
    }
    // The axes' directions, in the top left corner.
    let origin = (MARGIN + 40.0, MARGIN + 50.0);
    let names = [Some(across), Some(up), tool_axis];
    for (index, name) in names.into_iter().enumerate() {
        let Some(name) = name else { continue };
        let mut unit = [0.0; 3];
        unit[index] = 30.0;
        let (x, y) = View::Iso.project(unit);
        let end = (origin.0 + x, origin.1 - y);
        let _ = writeln!(
            out,
            r##"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="#444" stroke-width="1.2"/>"##,
            origin.0, origin.1, end.0, end.1
        );
        let _ = writeln!(
            labels,
            r#"<text x="{:.2}" y="{:.2}" font-weight="bold">{}</text>"#,
            end.0 + 2.0,
            end.1 + 4.0,
            char::from(name)
        );
    }
    labels.push_str("</g>\n");
    labels
}

/// The part's extent as a box in the isometric view, its height labelled
/// along the right edge: the depths that the grid on the plane below
/// cannot show.
fn extent_box(
    out: &mut String,
    labels: &mut String,
    pixel: &impl Fn(Point) -> (f64, f64),
    (low, high): (Point, Point),
) {
    let corner = |bits: usize| std::array::from_fn(|axis| if bits >> axis & 1 == 1 { high[axis] } else { low[axis] });
    let _ = writeln!(out, r#"<g id="extent" {EXTENT_STYLE}>"#);
    for from in 0..8 {
        for axis in [1, 2, 4].into_iter().filter(|&axis| from & axis == 0) {
            let (a, b) = (pixel(corner(from)), pixel(corner(from | axis)));
            line(out, a, b);
        }
    }
    let _ = writeln!(out, "</g>");
    let height = |z: f64| pixel([high[0], low[1], z]);
    let ticks = ticks(low[2], high[2]);
    let spacing = match ticks.as_slice() {
        [(a, _), (b, _), ..] => (height(*a).1 - height(*b).1).abs(),
        _ => 0.0,
    };
    // Too low a box for a scale (a flat part seen beside its length): its
    // top and bottom, above and below the corner.
    let marks = if spacing >= MIN_LABEL_SPACING {
        ticks.into_iter().map(|(z, label)| (height(z), label, 4.0)).collect()
    } else {
        vec![(height(high[2]), number(high[2]), -2.0), (height(low[2]), number(low[2]), 10.0)]
    };
    for ((x, y), label, shift) in marks {
        let _ = writeln!(labels, r#"<text x="{:.2}" y="{:.2}">{label}</text>"#, x + 6.0, y + shift);
    }
}

/// A line from `a` to `b` in the style of its group.
fn line(out: &mut String, a: (f64, f64), b: (f64, f64)) {
    let _ = writeln!(out, r#"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}"/>"#, a.0, a.1, b.0, b.1);
}

/// The least distance in pixels between two labels of a scale.
const MIN_LABEL_SPACING: f64 = 12.0;

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

/// A move from `from` along `path` to `to`, an arc in the view plane of
/// the axes `letters` as chords of at most 5°, the tool axis moving
/// evenly along it (a helix).
fn path_points(from: Point, path: Path, to: Point, letters: (u8, u8)) -> Vec<Point> {
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
    let radius = (from[0] - centre.0).hypot(from[1] - centre.1);
    let angle_of = |point: Point| (point[1] - centre.1).atan2(point[0] - centre.0);
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
            let share = i as f64 / pieces as f64;
            let angle = a0 + sign * sweep * share;
            [centre.0 + radius * angle.cos(), centre.1 + radius * angle.sin(), from[2] + (to[2] - from[2]) * share]
        })
        .collect()
}

fn colour(speed: f64, fastest: f64) -> &'static str {
    let bucket = ((speed / fastest) * PALETTE.len() as f64).floor() as usize;
    PALETTE[bucket.min(PALETTE.len() - 1)]
}

fn legend(out: &mut String, top: f64, fastest: f64, sketch: &Sketch, shown: &Shown) {
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
    if shown.compensated {
        let x = MARGIN + 260.0;
        let _ = writeln!(out, r#"<line x1="{x}" y1="{0}" x2="{1}" y2="{0}" {PROGRAMMED_STYLE}/>"#, y2 - 4.0, x + 24.0);
        let _ = writeln!(
            out,
            r#"<text x="{}" y="{y2}">programmed contour (G41/G42); solid: the tool centre</text>"#,
            x + 30.0
        );
    }
    let (across, up, tool_axis) = shown.axes;
    let view = match shown.view {
        View::Iso => "isometric view".to_owned(),
        View::Radius => format!("{}{} plane, {} as a radius", char::from(across), char::from(up), char::from(up)),
        View::Diameter => format!("{}{} plane, {} as a diameter", char::from(across), char::from(up), char::from(up)),
        View::Top => format!("{}{} plane", char::from(across), char::from(up)),
    };
    let extent = shown.extent.map_or(String::new(), |(low, high)| {
        let mut names = vec![across, up];
        names.extend(tool_axis);
        // A lathe's diameter view measures the part across the spindle.
        let factor = |i: usize| if i == 1 && shown.view == View::Diameter { 2.0 } else { 1.0 };
        let spans: Vec<String> = names
            .iter()
            .enumerate()
            .map(|(i, &name)| {
                format!("{} {}…{}", char::from(name), number(factor(i) * low[i]), number(factor(i) * high[i]))
            })
            .collect();
        format!(" · part {} mm", spans.join(", "))
    });
    let _ = writeln!(
        out,
        r#"<text x="{MARGIN}" y="{}">{view}{extent} · total time {} · {} breaks</text>"#,
        y2 + 22.0,
        ncc_analysis::clock(sketch.total_time),
        sketch.break_count
    );
    if let Some(drawn) = sketch.capped() {
        let _ = writeln!(
            out,
            r##"<text x="{MARGIN}" y="{}" fill="#d1342f" font-weight="bold">{}</text>"##,
            y2 + 44.0,
            escape(&capped_note(drawn, sketch.moves))
        );
    }
}

/// A coordinate as the legend writes it: to the µm, without trailing
/// zeros.
fn number(value: f64) -> String {
    let text = format!("{:.3}", value + 0.0);
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A part far longer than high gets its top and bottom on the box's
    /// edge, not a scale whose labels would overlap.
    #[test]
    fn a_flat_part_labels_only_its_top_and_bottom() {
        let (mut out, mut labels) = (String::new(), String::new());
        // A millimetre is a pixel: labels a millimetre apart would overlap.
        let pixel = |[u, _, w]: Point| (u, -w);
        extent_box(&mut out, &mut labels, &pixel, ([0.0, 0.0, -3.0], [200.0, 200.0, 5.0]));
        assert_eq!(out.matches("<line ").count(), 12, "{out}");
        let texts: Vec<&str> =
            labels.lines().map(|line| line.split('>').nth(1).unwrap().trim_end_matches("</text")).collect();
        assert_eq!(texts, ["5", "-3"], "{labels}");
    }
}
