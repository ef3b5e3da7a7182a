//! A run written back as a program (`ncc expand`) while it runs: every
//! move as a plain numbered block, with calls, jumps, cycles, parameters and
//! offsets resolved, that any CNC8x6 accepts and that runs the same moves.
//!
//! The program is absolute (G90) with the feed per minute (G94), in radius
//! programming (G75) on a machine with a diameter axis: positions
//! are written to the micrometre, F in whole mm/min (the average of a block
//! whose feed varies, under constant cutting speed), threads with their
//! lead and spindle speed, dwells in units of 10 ms, and the stops M00/M01
//! where the run had them. Arc centres are rounded so that the end point
//! stays on the circle within the control's 1 µm. Under radius compensation
//! the tool-centre path is written, so the program needs no correction
//! table; positions are written in the zero offset G53 of the machine's
//! tables, with the zero offsets, length corrections, recalculations
//! G35–G37 and transformations G38/G39/G31 the run had applied.

use std::io::{self, Write};

use smallvec::SmallVec;

use crate::{
    cnc8x6::interpreter::reset_frame,
    compensation::ToolElement,
    expand::{Expand, ExpandError, Unwritable, centre_offsets},
    machine::MachineConfig,
    tool_path::{Centred, CentredSteps, OwnCentred, tool_moves},
    trace::{Compensated, Motion, Path, Position, Step, StepSink, Stop, round3, slot},
    transform::{Frame, by_letter, over_axes},
};

/// The longest line the control reads (000:612).
const MAX_LINE: usize = 80;

/// Why a move is unwritable: the one move this writer cannot express.
const OUT_OF_PLANE: &str = "an arc turned out of its plane by a transformation (G38/G39/G31) is no arc of any plane";

/// Writes the moves of a run as program `%number` to `out` while the run
/// goes: a [`StepSink`] for `run::run_into` (a sink on a thread of
/// its own is not told the frames and the tool-centre path) that writes
/// the blocks of each step as it comes and keeps nothing of it, so that a
/// run of any length expands in the same memory.
#[derive(Debug)]
pub struct Expansion<W: Write> {
    writer: Writer<W>,
    axes: Vec<u8>,
    /// The frame the written program runs in.
    written: Frame,
    /// The run's frames so far.
    frames: Vec<Frame>,
    /// Radius compensation of the steps to come.
    centres: CentredSteps,
    /// What stopped the expansion: nothing is written after it.
    failure: Option<ExpandError>,
}

impl<W: Write> Expansion<W> {
    /// Starts program `%number`, with `title` as its header comment, for a
    /// run on `machine`.
    pub fn new(out: W, machine: &MachineConfig, number: u32, title: &str) -> Expansion<W> {
        let writer = Writer { out, number: 0, at: [0.0; 26], feed: None };
        let mut expansion = Expansion {
            writer,
            axes: machine.step_axes().to_vec(),
            written: reset_frame(machine),
            frames: Vec::new(),
            centres: CentredSteps::default(),
            failure: None,
        };
        let title: String = title.chars().filter(|&c| c != '"' && !c.is_control()).collect();
        let mut header = vec!["G90".to_owned(), "G94".to_owned(), "G53".to_owned()];
        // The trace keeps radii on a lathe's diameter axis.
        if machine.diameter_axis.is_some() {
            header.push("G75".to_owned());
        }
        let started =
            writeln!(expansion.writer.out, "%{number} \"{title}\"").and_then(|()| expansion.writer.block(header));
        expansion.failure = started.err().map(ExpandError::Io);
        expansion
    }

    /// Ends the program after the run, and hands back the output.
    pub fn finish(mut self) -> Result<W, ExpandError> {
        if let Some(failure) = self.failure {
            return Err(failure);
        }
        self.writer.block(vec!["M30".to_owned()])?;
        self.writer.out.write_all(b"*\n")?;
        self.writer.out.flush()?;
        Ok(self.writer.out)
    }

    /// Writes the blocks of `step`, which runs under radius compensation
    /// when `centred` says so.
    fn write(&mut self, step: &Step, centred: Option<&Centred<'_>>) -> Result<(), ExpandError> {
        let axes = &self.axes;
        let frames = Frames { step: &self.frames[step.frame], written: &self.written, axes };
        // Where the written program has the tool, in the step's frame: the
        // start of the pieces of the tool-centre path.
        let start = match centred {
            Some(_) => over_axes(&frames.to_step(&self.writer.at), axes),
            None => step.end,
        };
        let moves = tool_moves(step, &start, centred, axes);
        let mut blocks: SmallVec<[Vec<String>; 2]> = SmallVec::new();
        for tool_move in &moves {
            let to = by_letter(&tool_move.end, axes);
            let unwritable =
                || ExpandError::Unwritable(Unwritable { source: step.source, range: step.range, reason: OUT_OF_PLANE });
            let path = frames.path(&tool_move.path, &to).ok_or_else(unwritable)?;
            let to = frames.to_written(&to);
            blocks.push(self.writer.words(axes, step.motion, &path, &to, tool_move.feed, step.duration));
            if step.motion != Motion::None && step.motion != Motion::Dwell {
                self.writer.at = rounded(&to);
            }
        }
        let stop = match step.stop {
            Some(Stop::Program) => Some("M00".to_owned()),
            Some(Stop::Optional) => Some("M01".to_owned()),
            None => None,
        };
        if let (Some(stop), Some(last)) = (stop, blocks.last_mut()) {
            last.push(stop);
        }
        for words in blocks.into_iter().filter(|words| !words.is_empty()) {
            self.writer.block(words)?;
        }
        Ok(())
    }
}

impl<W: Write> StepSink for Expansion<W> {
    fn step(&mut self, step: Step) {
        let own = self.centres.next_step();
        if self.failure.is_some() {
            return;
        }
        let centred = own.as_ref().map(OwnCentred::centred);
        if let Err(failure) = self.write(&step, centred.as_ref()) {
            self.failure = Some(failure);
        }
    }

    fn references(&mut self, frames: &[Frame], compensated: &[Compensated], pieces: &[ToolElement]) {
        self.frames.extend_from_slice(frames.get(self.frames.len()..).unwrap_or_default());
        self.centres.references(compensated, pieces);
    }

    /// Nothing more is written after a failure, so the run need not go on.
    fn closed(&self) -> bool {
        self.failure.is_some()
    }
}

impl<W: Write> Expand for Expansion<W> {
    fn finish(self: Box<Self>) -> Result<(), ExpandError> {
        Expansion::finish(*self).map(drop)
    }
}

/// From the frame a step ran in to the frame the written program runs in:
/// the zero offset G53 of the machine's tables, without length correction,
/// recalculation or transformation, which the written positions resolve.
struct Frames<'a> {
    step: &'a Frame,
    written: &'a Frame,
    axes: &'a [u8],
}

impl Frames<'_> {
    fn to_written(&self, position: &Position) -> Position {
        let machine = self.step.to_machine(&over_axes(position, self.axes), self.axes);
        by_letter(&self.written.to_program(&machine, self.axes), self.axes)
    }

    fn to_step(&self, position: &Position) -> Position {
        let machine = self.written.to_machine(&over_axes(position, self.axes), self.axes);
        by_letter(&self.step.to_program(&machine, self.axes), self.axes)
    }

    /// The path ending at `to` in the written frame; `None` for an arc that
    /// a transformation turns out of its plane. A transformation keeps an
    /// arc's plane when it holds neither of the plane's axes, or is a
    /// planar one of exactly those two (a rotation in the plane keeps the
    /// direction of turning).
    fn path(&self, path: &Path, to: &Position) -> Option<Path> {
        let Path::Arc { plane: (a, b), centre, clockwise } = *path else { return Some(*path) };
        let keeps_plane = self.step.transformations.iter().all(|transformation| {
            let letters = transformation.letters();
            let held = [a, b].iter().filter(|letter| letters.contains(letter)).count();
            held == 0 || (held == 2 && letters.len() == 2)
        });
        if !keeps_plane {
            return None;
        }
        let mut point = *to;
        (point[slot(a)], point[slot(b)]) = (centre[0], centre[1]);
        let written = self.to_written(&point);
        Some(Path::Arc { plane: (a, b), centre: [written[slot(a)], written[slot(b)]], clockwise })
    }
}

#[derive(Debug)]
struct Writer<W> {
    out: W,
    /// The last block number written.
    number: u64,
    /// Where the written program has the tool, rounded as written.
    at: Position,
    /// The F in force in the written program, mm/min.
    feed: Option<i64>,
}

impl<W: Write> Writer<W> {
    /// The words of one move over the machine's `axes`; none for a move
    /// without motion or time.
    fn words(
        &mut self,
        axes: &[u8],
        motion: Motion,
        path: &Path,
        end: &Position,
        feed: Option<f64>,
        duration: f64,
    ) -> Vec<String> {
        let end = rounded(end);
        let changed: Vec<u8> = axes.iter().copied().filter(|&axis| end[slot(axis)] != self.at[slot(axis)]).collect();
        let coordinate = |axis: u8| format!("{}{:.3}", char::from(axis), end[slot(axis)]);
        match (motion, path) {
            (Motion::None, _) => Vec::new(),
            (Motion::Dwell, _) => vec!["G04".to_owned(), format!("Q{}", (duration * 100.0).round() as i64)],
            (Motion::Rapid | Motion::Feed, _) if changed.is_empty() && !matches!(path, Path::Arc { .. }) => Vec::new(),
            (Motion::Rapid, _) => {
                std::iter::once("G00".to_owned()).chain(changed.into_iter().map(coordinate)).collect()
            }
            (Motion::Feed, Path::Thread { lead, speed }) => {
                let mut words = vec!["G33".to_owned()];
                words.extend(changed.into_iter().map(coordinate));
                words.push(format!("F{lead:.3}"));
                words.push(format!("S{}", speed.round() as i64));
                // The lead replaced F in the written program.
                self.feed = None;
                words
            }
            (Motion::Feed, Path::Arc { plane: (a, b), centre, clockwise }) => {
                let mut words = vec![if *clockwise { "G02" } else { "G03" }.to_owned()];
                // The plane's axes first: the run takes the plane from the
                // first two axes written.
                words.extend([*a, *b].map(coordinate));
                words.extend(changed.into_iter().filter(|axis| axis != a && axis != b).map(coordinate));
                let start = [self.at[slot(*a)], self.at[slot(*b)]];
                let [i, j] = centre_offsets(start, [end[slot(*a)], end[slot(*b)]], *centre);
                words.push(format!("I{i:.3}"));
                words.push(format!("J{j:.3}"));
                words.extend(self.feed_word(feed));
                words
            }
            (Motion::Feed, Path::Straight) => {
                let mut words = vec!["G01".to_owned()];
                words.extend(changed.into_iter().map(coordinate));
                words.extend(self.feed_word(feed));
                words
            }
        }
    }

    /// F when the block's feed differs from the one in force.
    fn feed_word(&mut self, feed: Option<f64>) -> Option<String> {
        let feed = feed.map(|feed| (feed.round() as i64).max(1))?;
        (self.feed != Some(feed)).then(|| {
            self.feed = Some(feed);
            format!("F{feed}")
        })
    }

    /// Writes a block, continuing on further lines past the line length.
    fn block(&mut self, words: Vec<String>) -> io::Result<()> {
        self.number += 1;
        let mut line = format!("N{}", self.number);
        for word in words {
            if line.len() + 1 + word.len() > MAX_LINE {
                writeln!(self.out, "{line}")?;
                line = String::from(" ");
            }
            line.push(' ');
            line.push_str(&word);
        }
        writeln!(self.out, "{line}")
    }
}

fn rounded(position: &Position) -> Position {
    position.map(round3)
}

#[cfg(test)]
mod tests {
    use expect_test::expect;

    use std::{cell::RefCell, io, rc::Rc};

    use super::{ExpandError, Expansion, Unwritable};
    use crate::{
        compensation::ToolElement,
        machine::MachineConfig,
        run::{Compensated, Motion, NoFiles, Step, StepSink, Trace, run, run_into},
        transform::Frame,
    };

    fn run_text(text: &str) -> Trace {
        run(text, &NoFiles, &MachineConfig::default(), 10_000)
    }

    /// `text` run on `machine` and written as program `%number`.
    fn expand_on(machine: &MachineConfig, text: &str, number: u32, title: &str) -> Result<String, ExpandError> {
        let mut expansion = Expansion::new(Vec::new(), machine, number, title);
        run_into(text, &NoFiles, machine, 10_000, &mut expansion);
        expansion.finish().map(|written| String::from_utf8(written).unwrap())
    }

    fn expand(text: &str, number: u32, title: &str) -> String {
        expand_on(&MachineConfig::default(), text, number, title).unwrap()
    }

    /// A program with everything `expand` resolves: a subprogram called
    /// twice, a jump loop counting in a parameter, arithmetic, a drilling
    /// cycle, arcs in two planes, a helix, feed per revolution with the
    /// spindle, a thread, a dwell and a stop.
    const PROGRAM: &str = "%7 \"DEMO\"
N1 R10=0 R11=1. R12=2. R26=100 R27=800 R30=2. R31=-5. R32=5.
N2 G00 X10 Y0 Z5 S500 M03
N3 G71 L100 Q2
N4 G01 X20 F300
N5 R5=1101110 R6=17101220 G27
N6 GR20 L4 Q9999
N7 G81 X30
N8 G80 X40 M00
N9 G95 G03 X40 Z-5 I-5 J0 F0.2
N10 G94 G02 X50 Y12 Z-7 I0 J10 F400
N11 G33 Z-20. F1.5
N12 G04 Q50
N13 M30
N100 G79 L100
N101 G91 G01 X1 Y1 F600
N102 G90 G70
*
";

    /// Offsets, recalculations and transformations are resolved: the
    /// expansion runs in G53 the machine positions the original ran.
    #[test]
    fn offsets_and_transformations_are_written_as_machine_positions() {
        use crate::machine::{OffsetTable, ToolTable};
        let mut machine = MachineConfig::default();
        (machine.offsets, _) = OffsetTable::parse("$POS\nG53: X=1.0\nG54: X=100.0 Y=-50.0\n", &machine.axes);
        (machine.tools, _) = ToolTable::parse("$KOR\n01: R=0 X=0 Y=0 Z=25.0\n", &machine.axes);
        let text = "%1\nN1 G54 G00 X10 Y10 Z5 D1 &0010\nN2 G37 X5\nN3 G35 Y0\nN4 G01 X20 Y20 F500\nN5 G02 X30 Y10 I5 J-5\nN6 G34\nN7 G38 X0 Y0 I30\nN8 G38\nN9\nN10 G91 G03 X10 Y0 I5 J0\nN11 G01 Z-2\nN12 G38 I0\nN13 M30\n";
        let run_on = |text: &str| run(text, &NoFiles, &machine, 1000);
        let original = run_on(text);
        assert!(original.findings.is_empty(), "{:?}", original.findings);
        let expanded = expand_on(&machine, text, 1, "RESOLVED").unwrap();
        let again = run_on(&expanded);
        assert!(again.findings.is_empty(), "{:?}\n{expanded}", again.findings);
        let moves = |trace: &Trace| -> Vec<[i64; 3]> {
            (0..trace.steps.len())
                .filter(|&i| matches!(trace.steps[i].motion, Motion::Rapid | Motion::Feed))
                .map(|i| b"XYZ".map(|axis| (trace.axis(&trace.machine_end(i), axis) * 1000.0).round() as i64))
                .collect()
        };
        assert_eq!(moves(&again), moves(&original), "{expanded}");
        let (before, after) = (original.totals().total_time, again.totals().total_time);
        assert!((after - before).abs() < 1e-3 * before, "{before} s, expanded {after} s\n{expanded}");
        // A planar transformation of X and Z turns an arc of XY out of its plane.
        let text = "%1\nN1 G38 X0 Z0 I30\nN2 G38\nN3\nN4 G02 X10 Y0 I5 J0 F500\nN5 M30\n";
        let trace = run_text(text);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let Err(ExpandError::Unwritable(Unwritable { source: 0, range, .. })) =
            expand_on(&MachineConfig::default(), text, 1, "")
        else {
            panic!("the arc turned out of its plane is written");
        };
        assert_eq!(text[range].trim_end(), "N4 G02 X10 Y0 I5 J0 F500");
    }

    /// Under radius compensation the expansion writes the tool-centre path:
    /// it runs without G41/G42, in the same time.
    #[test]
    fn compensation_is_written_as_the_tool_centre_path() {
        let text = "%1\nN1 G92 D1 R0=5.\nN2 G00 X0 Y-20 D1\nN3 G41 G01 X0 Y0 F600\nN4 X50\nN5 G03 X70 Y20 I0 J20\nN6 G01 Y50\nN7 G40 X90 Y70\nN8 M30\n";
        let original = run_text(text);
        assert!(original.findings.is_empty(), "{:?}", original.findings);
        let expanded = expand(text, 1, "CENTRE");
        let again = run_text(&expanded);
        assert!(again.findings.is_empty(), "{:?}\n{expanded}", again.findings);
        let (before, after) = (original.totals().total_time, again.totals().total_time);
        assert!((after - before).abs() < 1e-3 * before, "{before} s, expanded {after} s");
        let centre_ends: Vec<[i64; 2]> = original
            .tool_centre
            .iter()
            .map(|piece| [piece.path.end().x, piece.path.end().y].map(|v| (v * 1000.0).round() as i64))
            .collect();
        let ends: Vec<[i64; 2]> = again.steps[2..again.steps.len() - 1]
            .iter()
            .map(|step| [b'X', b'Y'].map(|axis| (again.axis(&step.end, axis) * 1000.0).round() as i64))
            .collect();
        assert_eq!(ends, centre_ends, "{expanded}");
        expect![[r#"
            %1 "CENTRE"
            N1 G90 G94 G53
            N2 G00 Y-20.000
            N3 G01 Y5.000 F600
            N4 G01 X50.000
            N5 G03 X65.000 Y20.000 I0.000 J15.000 F450
            N6 G01 Y50.000 F600
            N7 G01 X90.000 Y70.000
            N8 M30
            *
        "#]]
        .assert_eq(&expanded);
    }

    #[test]
    fn the_expanded_program_runs_the_same_moves() {
        let original = run_text(PROGRAM);
        assert!(original.findings.is_empty(), "{:?}", original.findings);
        let expanded = expand(PROGRAM, 7, "DEMO EXPANDED");
        let again = run_text(&expanded);
        assert!(again.findings.is_empty(), "{:?}\n{expanded}", again.findings);
        let moves = |trace: &Trace| -> Vec<[i64; 3]> {
            trace
                .steps
                .iter()
                .filter(|step| matches!(step.motion, Motion::Rapid | Motion::Feed) && step.length > 0.0)
                .map(|step| b"XYZ".map(|axis| (trace.axis(&step.end, axis) * 1000.0).round() as i64))
                .collect()
        };
        assert_eq!(moves(&again), moves(&original), "{expanded}");
        // F is written in whole mm/min: the times agree to 0.1 %.
        let (before, after) = (original.totals().total_time, again.totals().total_time);
        assert!((after - before).abs() < 1e-3 * before, "{before} s, expanded {after} s");
        expect![[r#"
            %7 "DEMO EXPANDED"
            N1 G90 G94 G53
            N2 G00 X10.000 Z5.000
            N3 G01 X11.000 Y1.000 F600
            N4 G01 X12.000 Y2.000
            N5 G01 X20.000 F300
            N6 G01 X30.000
            N7 G00 Z2.000
            N8 G01 Z-5.000 F100
            N9 G00 Z5.000
            N10 G01 X40.000 F300 M00
            N11 G03 Z-5.000 X40.000 I-5.000 J0.000 F100
            N12 G02 X50.000 Y12.000 Z-7.000 I0.000 J10.000 F400
            N13 G33 Z-20.000 F1.500 S500
            N14 G04 Q50
            N15 M30
            *
        "#]]
        .assert_eq(&expanded);
    }

    /// An output the test reads while the expansion writes it.
    #[derive(Debug, Clone, Default)]
    struct Shared(Rc<RefCell<Vec<u8>>>);

    impl io::Write for Shared {
        fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
            self.0.borrow_mut().extend_from_slice(bytes);
            Ok(bytes.len())
        }

        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    /// The expansion, and the output's length after each step.
    struct Watched {
        expansion: Expansion<Shared>,
        output: Shared,
        lengths: Vec<usize>,
    }

    impl StepSink for Watched {
        fn step(&mut self, step: Step) {
            self.expansion.step(step);
            self.lengths.push(self.output.0.borrow().len());
        }

        fn references(&mut self, frames: &[Frame], compensated: &[Compensated], tool_centre: &[ToolElement]) {
            self.expansion.references(frames, compensated, tool_centre);
        }
    }

    /// Each step's block is written when the step comes, not at the end of
    /// the run: a loop of 3,000 moves, longer than a delivery batch.
    #[test]
    fn the_blocks_are_written_as_the_steps_come() {
        let text = "%1\nN1 G91 G01 X1 F600\nN2 X1 G73 L1 Q1499\nN3 M30\n";
        let output = Shared::default();
        let machine = MachineConfig::default();
        let expansion = Expansion::new(output.clone(), &machine, 1, "LOOP");
        let mut watched = Watched { expansion, output: output.clone(), lengths: Vec::new() };
        let trace = run_into(text, &NoFiles, &machine, 10_000, &mut watched);
        assert!(trace.findings.is_empty(), "{:?}", trace.findings);
        let Watched { expansion, lengths, .. } = watched;
        let header = "%1 \"LOOP\"\nN1 G90 G94 G53\n".len();
        // Blocks N2 to N3001, with the X of each: "N2 G01 X1.000 F600".
        let block = |n: usize| format!("N{n} G01 X{}.000{}\n", n - 1, if n == 2 { " F600" } else { "" }).len();
        let expected: Vec<usize> = (2..3002)
            .scan(header, |written, n| {
                *written += block(n);
                Some(*written)
            })
            .collect();
        assert_eq!(lengths[..3000], expected[..]);
        let written = String::from_utf8(expansion.finish().unwrap().0.take()).unwrap();
        assert!(written.ends_with("N3001 G01 X3000.000\nN3002 M30\n*\n"), "{}", &written[written.len() - 100..]);
    }
}
