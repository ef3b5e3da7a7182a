//! Streaming runs and checkpoints: a run hands on its steps as they are
//! final, and a run resumed from a checkpoint goes on as the whole run.

use std::ops::ControlFlow;

use ncc_syntax::TextSize;
use proptest::prelude::*;

use super::{lathe, lathe_with_nose};
use crate::{
    compensation::ToolElement,
    machine::MachineConfig,
    run::{NoFiles, resume_into, run, run_into},
    trace::{Checkpoint, Checkpoints, Compensated, DELIVERY_BATCH, Step, StepSink, Trace},
    transform::Frame,
};

/// Keeps the steps, checking that what they refer to comes before them,
/// and counts the steps of each delivery.
#[derive(Default)]
struct Deliveries {
    steps: Vec<Step>,
    frames: Vec<Frame>,
    pieces: Vec<ToolElement>,
    sizes: Vec<usize>,
}

impl StepSink for Deliveries {
    fn step(&mut self, step: Step) {
        assert!(step.frame < self.frames.len(), "the frame of step {} comes before it", self.steps.len());
        self.steps.push(step);
        if let Some(size) = self.sizes.last_mut() {
            *size += 1;
        }
    }

    fn references(&mut self, frames: &[Frame], _compensated: &[Compensated], pieces: &[ToolElement]) {
        assert!(pieces.iter().all(|piece| piece.block >= self.steps.len()), "pieces come before their steps");
        self.frames = frames.to_vec();
        self.pieces.extend_from_slice(pieces);
        self.sizes.push(0);
    }
}

/// A compensated contour longer than a delivery batch, then a local
/// subprogram called in a loop.
fn long_compensated_program() -> String {
    let mut text = String::from("O1\nT101\nG98 G00 X30. Z5.\nG42 G01 X20. Z0 F100.\n");
    for i in 0..2500 {
        text.push_str(&format!("X{}. Z-{}.\n", 20 + (i % 2) * 2, i + 1));
    }
    text.push_str(
        "G40 G00 X40.\n#1 = 0\nWHILE [#1 LT 3] DO1\nM97 P100 L2\n#1 = #1 + 1\nEND1\nM30\nN100 G01 W-1.\nM99\n",
    );
    text
}

#[test]
fn a_streamed_run_hands_on_the_steps_a_kept_run_keeps_a_batch_at_a_time() {
    let text = long_compensated_program();
    let machine = lathe_with_nose();
    let kept = run(&text, &NoFiles, &machine, 100_000);
    assert!(kept.findings.is_empty(), "{:?}", kept.findings);
    assert!(kept.tool_centre.len() > 2500);
    let mut delivered = Deliveries::default();
    let trace = run_into(&text, &NoFiles, &machine, 100_000, &mut delivered);
    assert!(trace.steps.is_empty());
    assert_eq!(delivered.steps, kept.steps);
    assert_eq!(delivered.frames, kept.frames);
    assert_eq!(delivered.pieces, kept.tool_centre);
    assert_eq!(Trace { steps: delivered.steps, ..trace }, kept);
    // The run held no more than a batch at a time, compensation or not.
    assert!(delivered.sizes.len() > 2, "{:?}", delivered.sizes);
    assert!(delivered.sizes.iter().all(|&size| size <= DELIVERY_BATCH), "{:?}", delivered.sizes);
}

/// Takes steps until it has `room` of them, then is closed.
struct Closing {
    taken: usize,
    room: usize,
}

impl StepSink for Closing {
    fn step(&mut self, _step: Step) {
        self.taken += 1;
    }

    fn closed(&self) -> bool {
        self.taken >= self.room
    }
}

#[test]
fn a_streamed_run_ends_soon_after_its_sink_closes() {
    let text = "O1\nG98 G01 F1000.\nN1 U0.002\nGOTO 1\n";
    let mut sink = Closing { taken: 0, room: 1 };
    let trace = run_into(text, &NoFiles, &lathe(), 1_000_000, &mut sink);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    assert!(sink.taken <= 2 * DELIVERY_BATCH, "{} steps after the sink closed", sink.taken);
    assert!(trace.blocks_run <= 4 * DELIVERY_BATCH, "{} blocks run", trace.blocks_run);
}

/// Wants one checkpoint, at block `at`, and ends the run there.
struct StopAt {
    at: usize,
}

impl StepSink for StopAt {
    fn step(&mut self, _step: Step) {}

    fn checkpoint_wanted(&mut self, block: usize, _offset: TextSize) -> bool {
        block == self.at
    }

    fn checkpoint(&mut self, _checkpoint: Checkpoint) -> ControlFlow<()> {
        ControlFlow::Break(())
    }
}

/// Checks that a run of `text` resumed from each of its checkpoints (one
/// every `every` blocks) goes on as the whole run: the same steps, and
/// after what the run reported up to the checkpoint, the same findings and
/// tool-centre path; it takes the same checkpoints after it.
fn assert_resumes_as_the_whole_run(text: &str, machine: &MachineConfig, every: usize) -> Vec<usize> {
    let budget = 20_000;
    let mut whole = Checkpoints { every, ..Checkpoints::default() };
    let trace = resume_into(None, text, &NoFiles, machine, budget, &mut whole);
    for checkpoint in &whole.taken {
        let at = checkpoint.block();
        let before = run_into(text, &NoFiles, machine, budget, &mut StopAt { at });
        let mut resumed = Checkpoints { before: checkpoint.steps(), every, ..Checkpoints::default() };
        let after = resume_into(Some(checkpoint), text, &NoFiles, machine, budget, &mut resumed);
        assert_eq!(resumed.steps, whole.steps[checkpoint.steps()..], "from block {at}");
        assert_eq!([&before.findings[..], &after.findings[..]].concat(), trace.findings, "from block {at}");
        assert_eq!([&before.tool_centre[..], &after.tool_centre[..]].concat(), trace.tool_centre, "from block {at}");
        assert_eq!([&before.compensated[..], &after.compensated[..]].concat(), trace.compensated, "from block {at}");
        assert_eq!((&after.frames, after.blocks_run), (&trace.frames, trace.blocks_run), "from block {at}");
        let later: Vec<&Checkpoint> = whole.taken.iter().filter(|c| c.block() >= at).collect();
        assert_eq!(resumed.taken.len(), later.len(), "from block {at}");
        for (again, first) in resumed.taken.iter().zip(later) {
            assert!(again.same_course(first) && again.offset() == first.offset(), "from block {at}");
        }
    }
    whole.taken.iter().map(Checkpoint::block).collect()
}

#[test]
fn a_run_resumed_from_a_checkpoint_goes_on_as_the_whole_run() {
    let text = long_compensated_program();
    let blocks = assert_resumes_as_the_whole_run(&text, &lathe_with_nose(), 1);
    // Up to G42's block, then none until G40's has run; the loop's blocks
    // up to the first call of the subprogram after M30, and none after it.
    assert_eq!(blocks, [0, 1, 2, 3, 2505, 2506, 2507]);
}

#[test]
fn checkpoints_skip_calls_compensation_later_loop_passes_and_spans_a_later_cycle_reads_back() {
    let text = "O1\nT101\nG98 G00 X30. Z5. F100.\nG71 P10 Q20 U0.3 W0.1 D1.\nN10 G00 X10.\nG01 Z0\nX20.\nZ-10.\nN20 G00 X30.\nG00 Z5.\nG70 P10 Q20\n#1 = 0\nWHILE [#1 LT 2] DO1\n#1 = #1 + 1\nEND1\nG42 G01 W-1.\nW-1.\nG40 G00 U2.\nM97 P100\nM30\nN100 G01 W-1.\nM99\n";
    let mut sink = Checkpoints { every: 1, ..Checkpoints::default() };
    let trace = resume_into(None, text, &NoFiles, &lathe_with_nose(), 1000, &mut sink);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
    let lines: Vec<&str> = sink.taken.iter().map(|c| text[usize::from(c.offset())..].lines().next().unwrap()).collect();
    // Not between the contour's start and G70, which reads it (G71 goes
    // on after the contour); each loop block once; not under G42 before
    // the cancel has run; none after the call of the subprogram after M30.
    assert_eq!(
        lines,
        [
            "O1",
            "T101",
            "G98 G00 X30. Z5. F100.",
            "G71 P10 Q20 U0.3 W0.1 D1.",
            "#1 = 0",
            "WHILE [#1 LT 2] DO1",
            "#1 = #1 + 1",
            "END1",
            "G42 G01 W-1.",
            "M97 P100"
        ]
    );
    assert_resumes_as_the_whole_run(text, &lathe_with_nose(), 1);
}

/// The checkpoints of a run of `text`, one every `every` blocks.
fn checkpoints(text: &str, every: usize) -> Vec<Checkpoint> {
    let mut sink = Checkpoints { every, ..Checkpoints::default() };
    resume_into(None, text, &NoFiles, &lathe(), 10_000, &mut sink);
    sink.taken
}

/// Modal state and a variable set early, then moves, then a jump back.
fn resumable_program(first_x: &str) -> String {
    let mut text = format!("O1\nG00 X{first_x} Z5. M03 S1000\n#100 = 5.\nG98 G01 Z-1. F300.\n");
    for i in 0..40 {
        text.push_str(&format!("X{}. Z#100\n", i * 3));
    }
    text.push_str("N60 U2.\nIF [#100 LT 8] GOTO 70\n#100 = #100 + 1\nGOTO 60\nN70 M30\n");
    text
}

#[test]
fn checkpoints_after_an_edit_take_the_same_course_once_the_edit_no_longer_matters() {
    let before = checkpoints(&resumable_program("0"), 7);
    assert_eq!(before.iter().map(Checkpoint::block).collect::<Vec<_>>(), [0, 7, 14, 21, 28, 35, 42]);
    // An absolute move written longer: the course is the same from the
    // next move on, three bytes later.
    let after = checkpoints(&resumable_program("1234"), 7);
    assert_eq!(after.len(), before.len());
    for (after, before) in after.iter().zip(&before).skip(1) {
        let shifted = before.shifted(3, 0, 0);
        assert_eq!(after.offset(), shifted.offset());
        assert!(after.same_course(&shifted));
    }
    // A variable the moves read carries the difference to the end.
    let deeper = checkpoints(&resumable_program("0").replace("#100 = 5.", "#100 = 6."), 7);
    assert!(deeper.iter().zip(&before).skip(1).all(|(after, before)| !after.same_course(before)));
    // A block numbered 70 before them: the GOTO after them goes there.
    let renumbered = checkpoints(&resumable_program("0").replace("#100 = 5.", "N70 #100 = 5."), 7);
    assert!(renumbered.iter().zip(&before).skip(1).all(|(after, before)| !after.same_course(&before.shifted(4, 0, 0))));
}

#[test]
fn a_block_jumped_over_before_a_checkpoint_is_part_of_its_course() {
    // N20 runs only after the checkpoints: its text decides the run.
    let program =
        |x: &str| format!("O1\nG98 G01 F100.\nGOTO 30\nN20 G01 U{x}\nM99 P40\nN30 U1.\nW-1.\nM97 P20\nN40 M30\n");
    let (short, long) = (checkpoints(&program("1."), 1), checkpoints(&program("10."), 1));
    assert_eq!(short.iter().map(Checkpoint::block).collect::<Vec<_>>(), [0, 1, 2, 5, 6, 7, 8]);
    assert!(!short[4].same_course(&long[4].shifted(-1, 0, 0)));
    assert!(short[2].same_course(&long[2]));
}

/// Pieces of programs to put together: moves, variables, a WHILE loop, a
/// local subprogram and a program of the file called, a jump over a
/// block, a roughing cycle over the contour after it and the finishing
/// cycle after that, a compensated stretch, a box cycle, work offsets, a
/// dwell. `{n}` is a number of its own for each piece.
const PIECES: [&str; 13] = [
    "G01 U-1. W-1.\n",
    "G00 U1.5 W0.5\n",
    "#100 = #100 + 1\nIF [#100 GT 3] THEN #101 = #100\n",
    "#5 = 0\nWHILE [#5 LT 2] DO1\nG01 U0.5 W-0.5\n#5 = #5 + 1\nEND1\n",
    "M97 P9000 L2\n",
    "M98 P2000\n",
    "GOTO {n}\nG01 U7.\nN{n} G01 W-1.\n",
    "G00 X30. Z5.\nG71 P{n}1 Q{n}2 U0.3 W0.1 D1.\nN{n}1 G00 X10.\nG01 Z0\nX20.\nZ-10.\nN{n}2 G00 X30.\nG00 Z5.\nG70 P{n}1 Q{n}2\n",
    "G42 G01 U1. W-1.\nW-2.\nU2. W-1.\nG40 G00 U4.\n",
    "G90 U-2. W-3.\nW-1.\nG00 U3.\n",
    "G55\nG00 U1.\n",
    "G54 G52 W-1.\nG00 U-1.\n",
    "G04 P100\n",
];

/// A program of `pieces` between a start and the subprograms.
fn generated(pieces: &[usize]) -> String {
    let mut text = String::from("O1000\nT101\nG18 G98 F300.\nG00 X40. Z5.\n");
    for (n, &piece) in pieces.iter().enumerate() {
        text.push_str(&PIECES[piece].replace("{n}", &(100 + n).to_string()));
    }
    text.push_str("M30\nN9000 G01 U0.2 W-0.2\nM99\nO2000\nG01 U-0.2 W-0.1\nM99\n");
    text
}

#[test]
fn the_pieces_of_generated_programs_run_without_findings() {
    let machine = MachineConfig { offsets: super::lathe_with_offsets().offsets, ..lathe_with_nose() };
    let trace = run(&generated(&(0..PIECES.len()).collect::<Vec<_>>()), &NoFiles, &machine, 10_000);
    assert!(trace.findings.is_empty(), "{:?}", trace.findings);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Over generated programs with calls, loops, jumps, cycles and
    /// compensation, a run resumed from any checkpoint goes on as the
    /// whole run.
    #[test]
    fn runs_resumed_from_any_checkpoint_go_on_as_whole_runs(
        pieces in proptest::collection::vec(0..PIECES.len(), 1..24),
        every in 1usize..4,
    ) {
        let machine = MachineConfig { offsets: super::lathe_with_offsets().offsets, ..lathe_with_nose() };
        assert_resumes_as_the_whole_run(&generated(&pieces), &machine, every);
    }
}
