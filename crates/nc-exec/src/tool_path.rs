//! The path the tool centre runs, step by step: a step's own move, or under
//! radius compensation G41/G42 the pieces of the tool-centre path that
//! belong to it ([`crate::compensation`]). The control moves the tool
//! centre along the equidistants and displays where it is (02 §1.6–1.9; on
//! a lathe the theoretical tip, 02 §1.11), so the positions `ncc run`
//! reports, the moves `ncc plot` draws and the blocks `ncc expand` writes
//! are these; a step's end ([`Step::end`]) stays the programmed point.

use std::collections::VecDeque;

use nalgebra::Point2;
use smallvec::{SmallVec, smallvec};

use crate::{
    compensation::{Element, ToolElement},
    trace::{Axes, Compensated, MAX_AXES, Path, Step, Trace},
};

/// A step's part in radius compensation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Centred<'a> {
    /// The plane's axes, the order of the pieces' coordinates.
    pub plane: (u8, u8),
    /// The step's own pieces of the tool-centre path, in path order.
    pub pieces: &'a [ToolElement],
    /// Where the tool-centre path ends before them: the end of the last
    /// piece of the compensation's earlier steps, if it has any.
    pub before: Option<Point2<f64>>,
}

/// A step's part in radius compensation, for a sink that is handed the
/// steps one by one: [`Centred`] with the pieces its own.
#[derive(Debug, Clone, PartialEq)]
pub struct OwnCentred {
    pub plane: (u8, u8),
    pub pieces: SmallVec<[ToolElement; 2]>,
    pub before: Option<Point2<f64>>,
}

impl OwnCentred {
    pub fn centred(&self) -> Centred<'_> {
        Centred { plane: self.plane, pieces: &self.pieces, before: self.before }
    }
}

/// What a [`StepSink`](crate::trace::StepSink) keeps of radius
/// compensation to give each step handed to it its part: the spans and the
/// pieces of the tool-centre path it was told of, and where the path ended.
#[derive(Debug, Clone, Default)]
pub struct CentredSteps {
    spans: VecDeque<Compensated>,
    pieces: VecDeque<ToolElement>,
    /// The step of the last piece handed out, and where it ends.
    path_end: Option<(usize, Point2<f64>)>,
    /// The index of the step to come.
    next: usize,
}

impl CentredSteps {
    /// Takes what the sink is told before the steps they concern.
    pub fn references(&mut self, compensated: &[Compensated], pieces: &[ToolElement]) {
        // The last span may have grown since.
        let first = compensated.partition_point(|span| span.steps.end <= self.next);
        self.spans.clear();
        self.spans.extend(compensated[first..].iter().cloned());
        self.pieces.extend(pieces);
    }

    /// The part of the step to come; `None` outside compensation.
    pub fn next_step(&mut self) -> Option<OwnCentred> {
        let index = self.next;
        self.next += 1;
        while self.spans.front().is_some_and(|span| span.steps.end <= index) {
            self.spans.pop_front();
        }
        let mut own: SmallVec<[ToolElement; 2]> = SmallVec::new();
        while let Some(piece) = self.pieces.front().filter(|piece| piece.block == index) {
            own.push(*piece);
            self.pieces.pop_front();
        }
        let span = self.spans.front().filter(|span| span.steps.contains(&index))?;
        let before = self.path_end.filter(|&(block, _)| block >= span.steps.start).map(|(_, end)| end);
        if let Some(last) = own.last() {
            self.path_end = Some((index, last.path.end()));
        }
        Some(OwnCentred { plane: span.plane, pieces: own, before })
    }
}

/// A move of the tool centre, to `end` over the machine's axes in the
/// program coordinates of its step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolMove {
    pub path: Path,
    pub end: Axes,
    /// The path feed in mm/min: the step's, scaled on a compensated arc.
    pub feed: Option<f64>,
}

/// Where the tool centre is at the end of a step that ends at `end` (its
/// programmed end over the machine's `axes`): `end`, but under radius
/// compensation, in the plane, where the tool-centre path ends so far (the
/// run's end fixes the last element, [`crate::compensation::Compensator::finish`]);
/// a compensated step with no path of its own or before it keeps its
/// programmed point.
pub fn tool_end(end: &Axes, centred: Option<&Centred<'_>>, axes: &[u8]) -> Axes {
    let Some(centred) = centred else { return *end };
    let point = centred.pieces.last().map(|piece| piece.path.end()).or(centred.before);
    point.map_or(*end, |point| in_plane(end, centred.plane, point, axes))
}

/// The moves the tool centre makes in `step`, which it starts at `start`
/// (over the machine's `axes`, in the step's program coordinates): the
/// step's own move, or under radius compensation its pieces of the
/// tool-centre path, the axes outside the plane moving with the last of
/// them; a compensated step without pieces of its own moves outside the
/// plane only.
pub fn tool_moves(step: &Step, start: &Axes, centred: Option<&Centred<'_>>, axes: &[u8]) -> SmallVec<[ToolMove; 2]> {
    let Some(compensation) = centred else {
        return smallvec![ToolMove { path: step.path, end: step.end, feed: step.feed }];
    };
    let last = compensation.pieces.len().saturating_sub(1);
    let mut moves: SmallVec<[ToolMove; 2]> = compensation
        .pieces
        .iter()
        .enumerate()
        .map(|(k, piece)| {
            let others = if k == last { &step.end } else { start };
            let path = match piece.path {
                Element::Arc { centre, clockwise, .. } => {
                    Path::Arc { plane: compensation.plane, centre: [centre.x, centre.y], clockwise }
                }
                Element::Line { .. } => Path::Straight,
            };
            let end = in_plane(others, compensation.plane, piece.path.end(), axes);
            ToolMove { path, end, feed: step.feed.map(|feed| feed * piece.feed_scale) }
        })
        .collect();
    if moves.is_empty() {
        moves.push(ToolMove { path: Path::Straight, end: tool_end(&step.end, centred, axes), feed: step.feed });
    }
    moves
}

/// `values` with the plane's axes at `point`.
fn in_plane(values: &Axes, (a, b): (u8, u8), point: Point2<f64>, axes: &[u8]) -> Axes {
    let mut moved = *values;
    for (letter, value) in [(a, point.x), (b, point.y)] {
        if let Some(slot) = axes.iter().position(|&axis| axis == letter) {
            moved[slot] = value;
        }
    }
    moved
}

impl Trace {
    /// Step `index`'s part in radius compensation, if it ran under it (the
    /// trace need not keep its steps).
    pub fn centred(&self, index: usize) -> Option<Centred<'_>> {
        let span = self.compensated.partition_point(|span| span.steps.start <= index).checked_sub(1)?;
        let span = &self.compensated[span];
        if !span.steps.contains(&index) {
            return None;
        }
        let first = self.tool_centre.partition_point(|piece| piece.block < index);
        let own = self.tool_centre[first..].partition_point(|piece| piece.block == index);
        let before = self.tool_centre[..first].last().filter(|piece| piece.block >= span.steps.start);
        Some(Centred {
            plane: span.plane,
            pieces: &self.tool_centre[first..first + own],
            before: before.map(|piece| piece.path.end()),
        })
    }

    /// Where the tool centre is at the end of step `index`, which ends at
    /// `end` ([`Step::end`]; the trace need not keep its steps), in the
    /// step's program coordinates.
    pub fn tool_end(&self, index: usize, end: &Axes) -> Axes {
        tool_end(end, self.centred(index).as_ref(), &self.axes)
    }

    /// Where the tool centre is at the end of step `index`, in machine
    /// coordinates.
    pub fn tool_machine_end(&self, index: usize) -> Axes {
        let step = &self.steps[index];
        self.frames[step.frame].to_machine(&self.tool_end(index, &step.end), &self.axes)
    }

    /// Where the tool centre is at the start of step `index`, in machine
    /// coordinates: where the step before it left it, or the machine zero.
    pub fn tool_machine_start(&self, index: usize) -> Axes {
        index.checked_sub(1).map_or([0.0; MAX_AXES], |before| self.tool_machine_end(before))
    }

    /// Where the tool centre is at the start of step `index`, in the
    /// program coordinates the step runs in.
    pub fn tool_start_of(&self, index: usize) -> Axes {
        self.frames[self.steps[index].frame].to_program(&self.tool_machine_start(index), &self.axes)
    }

    /// The moves the tool centre makes in step `index`, in the program
    /// coordinates the step runs in.
    pub fn tool_moves(&self, index: usize) -> SmallVec<[ToolMove; 2]> {
        tool_moves(&self.steps[index], &self.tool_start_of(index), self.centred(index).as_ref(), &self.axes)
    }
}

#[cfg(test)]
mod tests {
    use super::ToolMove;
    use crate::{
        compensation::ToolElement,
        machine::MachineConfig,
        run::{Compensated, NoFiles, Path, Step, StepSink, Trace, run, run_into},
        transform::Frame,
    };

    fn run_text(text: &str) -> Trace {
        let trace = run(text, &NoFiles, &MachineConfig::default(), 10_000);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        trace
    }

    /// The tool-centre ends of the steps in X and Y, to the micrometre.
    fn centre_ends(trace: &Trace) -> Vec<(f64, f64)> {
        (0..trace.steps.len())
            .map(|index| {
                let end = trace.tool_end(index, &trace.steps[index].end);
                (trace.axis(&end, b'X'), trace.axis(&end, b'Y'))
            })
            .collect()
    }

    /// Radius 5 on the left (G41) of a corner turning left: the start move
    /// ends on the first line's normal at (0, 5), the inside corner is the
    /// intersection (45, 5), the last line ends on its normal at (45, 50),
    /// and G40 leaves from there for the programmed (70, 70); Z moving
    /// alone under compensation leaves the tool where it is in the plane.
    #[test]
    fn under_compensation_the_tool_centre_is_on_the_equidistant() {
        let text = "%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\nN4 X50\nN5 Z-2\nN6 Y50\nN7 G40 X70 Y70\nN8 M30\n";
        let trace = run_text(text);
        let centre = centre_ends(&trace);
        assert_eq!(
            centre[..8],
            [(0.0, 0.0), (0.0, -20.0), (0.0, 5.0), (45.0, 5.0), (45.0, 5.0), (45.0, 50.0), (70.0, 70.0), (70.0, 70.0)]
        );
        // The programmed points stay the steps' ends.
        assert_eq!((trace.axis(&trace.steps[3].end, b'X'), trace.axis(&trace.steps[3].end, b'Y')), (50.0, 0.0));
        // Each step starts where the tool centre ended the one before; Z
        // moves alone, and the compensated lines run from corner to corner.
        let start = trace.tool_start_of(5);
        assert_eq!((trace.axis(&start, b'X'), trace.axis(&start, b'Y'), trace.axis(&start, b'Z')), (45.0, 5.0, -2.0));
        let moves = trace.tool_moves(4);
        assert_eq!(moves.len(), 1);
        let end = moves[0].end;
        assert_eq!((trace.axis(&end, b'X'), trace.axis(&end, b'Y'), trace.axis(&end, b'Z')), (45.0, 5.0, -2.0));
        let end = trace.tool_machine_end(5);
        assert_eq!((trace.axis(&end, b'X'), trace.axis(&end, b'Y')), (45.0, 50.0));
    }

    /// With arcs at outside corners (machine constant 339 decade 8 = 1)
    /// the block after the corner runs the inserted arc, then its own
    /// line, both at the block's feed.
    #[test]
    fn an_outside_corner_is_an_arc_of_the_block_after_it() {
        let text =
            "%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G42 G01 X0 Y0 F600\nN4 X50\nN5 Y50\nN6 G40 X70 Y70\nN7 M30\n";
        let mut machine = MachineConfig::default();
        machine.constants.insert(339, 10_000_000);
        let trace = run(text, &NoFiles, &machine, 10_000);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let moves = trace.tool_moves(4);
        let ends: Vec<(f64, f64)> =
            moves.iter().map(|m: &ToolMove| (trace.axis(&m.end, b'X'), trace.axis(&m.end, b'Y'))).collect();
        assert_eq!(ends, [(55.0, 0.0), (55.0, 50.0)]);
        assert_eq!(moves[0].path, Path::Arc { plane: (b'X', b'Y'), centre: [50.0, 0.0], clockwise: false });
        assert_eq!((moves[0].feed, moves[1].feed), (Some(600.0), Some(600.0)));
        assert_eq!(centre_ends(&trace)[3], (50.0, -5.0));
        // Its length and time are both: the quarter circle of radius 5 and
        // the 50 mm line.
        let length = std::f64::consts::FRAC_PI_2 * 5.0 + 50.0;
        assert!((trace.steps[4].length - length).abs() < 1e-9, "{} mm", trace.steps[4].length);
        assert!((trace.steps[4].duration - length / 10.0).abs() < 1e-9, "{} s", trace.steps[4].duration);
    }

    /// A run that ends with compensation in force fixes its last element
    /// as a G40 block would: the tool centre stays on the normal at the
    /// last programmed point, and the step's length is its path there;
    /// so at the end of the file, and before a block the control refuses.
    #[test]
    fn a_run_ending_under_compensation_ends_on_the_last_normal() {
        let contour = "%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\nN4 X50\nN5 Y50\n";
        let trace = run(contour, &NoFiles, &MachineConfig::default(), 10_000);
        assert!(trace.findings.iter().all(|finding| !finding.stops()), "{:?}", trace.findings);
        assert_eq!(centre_ends(&trace).last(), Some(&(45.0, 50.0)));
        assert_eq!(trace.steps.last().map(|step| step.length), Some(45.0));
        // An arc too small for the tool on its inside stops the run.
        let refused = format!("{contour}N6 G03 X50 Y56 I0 J3\nN7 M30\n");
        let trace = run(&refused, &NoFiles, &MachineConfig::default(), 10_000);
        let fatal: Vec<&str> =
            trace.findings.iter().filter(|f| f.stops()).map(|f| refused[f.range].trim_end()).collect();
        assert_eq!(fatal, ["N6 G03 X50 Y56 I0 J3"]);
        let line = trace.steps.iter().rposition(|step| refused[step.range].starts_with("N5")).expect("N5 ran");
        assert_eq!(centre_ends(&trace)[line], (45.0, 50.0));
        assert_eq!(trace.steps[line].length, 45.0);
    }

    /// What a streaming sink is told besides the steps.
    #[derive(Default)]
    struct Referring {
        steps: Vec<Step>,
        frames: Vec<Frame>,
        compensated: Vec<Compensated>,
        pieces: Vec<ToolElement>,
    }

    impl StepSink for Referring {
        fn step(&mut self, step: Step) {
            assert!(step.frame < self.frames.len(), "the frame of step {} comes before it", self.steps.len());
            self.steps.push(step);
        }

        fn references(&mut self, frames: &[Frame], compensated: &[Compensated], pieces: &[ToolElement]) {
            assert!(pieces.iter().all(|piece| piece.block >= self.steps.len()), "pieces come before their steps");
            self.frames = frames.to_vec();
            self.compensated = compensated.to_vec();
            self.pieces.extend_from_slice(pieces);
        }
    }

    /// A streaming sink gets every frame and piece of the tool-centre path
    /// before the steps that need them: a compensated contour longer than
    /// a delivery batch, under a zero offset that changes.
    #[test]
    fn a_streaming_sink_is_told_the_frames_and_the_tool_centre_before_the_steps() {
        let mut text = String::from("%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\n");
        for i in 0..2500 {
            text.push_str(&format!("N{} X{} Y{}\n", 4 + i, (i + 1) * 2, (i % 2) * 3));
        }
        text.push_str("N3000 G40 X6000 Y-30\nN3001 G92 X0 Y0\nN3002 G01 X10\nN3003 M30\n");
        let kept = run_text(&text);
        let mut told = Referring::default();
        let trace = run_into(&text, &NoFiles, &MachineConfig::default(), 10_000, &mut told);
        assert_eq!(told.steps, kept.steps);
        assert_eq!(told.frames, kept.frames);
        assert_eq!(told.compensated, kept.compensated);
        assert!(kept.tool_centre.len() > 2500);
        assert_eq!(told.pieces, kept.tool_centre);
        assert_eq!(trace.tool_centre, kept.tool_centre);
    }
}
