//! Thread cutting G33: lead, end point, run-out and lead-in, the mandatory
//! empty block and the block that follows it.

use ncc_catalog::{AddressRole, Dialect};

use nc_exec::known::Known;

use crate::{
    Diagnostic,
    cnc8x6::flow::{FlowCheck, ModalState, Visit},
    diagnostic::declare_rules,
    lower::{BlockData, Value},
};

declare_rules! {
    MISSING_THREAD_LEAD = "T601", "missing-thread-lead", Error, "G33 with no lead F programmed.";
    THREAD_LEAD_TOO_LARGE = "T602", "thread-lead-too-large", Error, "A thread lead above 99.99 mm/rev written directly under F.";
    THREAD_WITHOUT_END_POINT = "T603", "thread-without-end-point", Error, "A G33 block without an end-point coordinate.";
    MISSING_EMPTY_BLOCK_AFTER_THREAD = "T604", "missing-empty-block-after-thread", Error, "A G33 block with run-out J or lead-in E not followed by an empty block.";
    THREAD_EXIT_MISSING_AXES = "T605", "thread-exit-missing-axes", Error, "The block after a thread's empty block does not program every axis.";
    NEGATIVE_RUNOUT = "T606", "negative-runout", Error, "A negative run-out length J.";
    SPINDLE_NOT_RUNNING = "T607", "spindle-not-running", Warning, "G33 while the spindle is stopped.";
    DECIMAL_POINT_REQUIRED = "B213", "decimal-point-required", Error, "A thread lead-in E written without its mandatory decimal point.";
}

/// What the blocks after a thread with run-out or lead-in must be.
#[derive(Default, Clone, Copy, PartialEq, Eq)]
enum After {
    #[default]
    Nothing,
    EmptyBlock,
    AllAxes,
}

#[derive(Default)]
pub(crate) struct Threads {
    after: After,
}

impl FlowCheck for Threads {
    fn block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        let block = visit.block;
        match self.after {
            After::EmptyBlock => {
                self.after = After::Nothing;
                if !block.is_empty() {
                    let head = block.words.first().map_or(visit.range(Default::default()), |w| visit.range(w.range));
                    out.push(Diagnostic::new(
                        &MISSING_EMPTY_BLOCK_AFTER_THREAD,
                        head,
                        "after a thread with run-out (J) or lead-in (E) the next block must be empty (only its number); insert an empty block before this one",
                    ));
                } else {
                    self.after = After::AllAxes;
                }
            }
            After::AllAxes => {
                self.after = After::Nothing;
                check_all_axes(visit, out);
            }
            After::Nothing => {}
        }
        if visit.after.g(0) == Some(Some(33)) {
            self.thread_block(visit, out);
        }
    }
}

impl Threads {
    fn thread_block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        let block = visit.block;
        let code = visit.code_range(b'G', 33);
        let head = code.or_else(|| block.words.first().map(|w| visit.range(w.range))).unwrap_or_default();
        let catalogue = Dialect::Cnc8x6.catalogue();
        let has_axis = block.words.iter().any(|w| catalogue.role_of(w.letter) == Some(AddressRole::Axis));
        if !has_axis {
            // A block that only sets G33 and its data is not a thread pass
            // unless G33 is written in it.
            if code.is_some() {
                out.push(Diagnostic::new(
                    &THREAD_WITHOUT_END_POINT,
                    head,
                    "G33 cuts a thread to an end point: write the coordinate where the thread ends (e.g. Z-50.)",
                ));
            }
            return;
        }
        if visit.after.feed == Known::Is(None) {
            out.push(Diagnostic::new(&MISSING_THREAD_LEAD, head, "G33 needs the thread lead in F (mm/rev), e.g. F1.5"));
        }
        let literal = |letter| {
            block.word(letter).and_then(|w| match &w.value {
                Some(Value::Literal(value)) => Some((w, *value)),
                _ => None,
            })
        };
        if let Some((word, lead)) = literal(b'F').filter(|(_, lead)| lead.has_point() && lead.to_f64() > 99.99) {
            out.push(Diagnostic::new(
                &THREAD_LEAD_TOO_LARGE,
                visit.range(word.range),
                format!("a lead of {lead} mm/rev is above the 99.99 that F takes directly; assign it to a parameter and write FR10 (R10={lead})"),
            ));
        }
        if let Some((word, _)) = literal(b'J').filter(|(_, runout)| runout.is_negative()) {
            out.push(Diagnostic::new(
                &NEGATIVE_RUNOUT,
                visit.range(word.range),
                "the run-out length J is always positive, whatever the direction of the thread",
            ));
        }
        // Only the lead-in needs the point: elsewhere E is a centre
        // refinement or an angle divisor.
        if let Some((word, lead_in)) = literal(b'E').filter(|(_, lead_in)| !lead_in.has_point()) {
            out.push(Diagnostic::new(
                &DECIMAL_POINT_REQUIRED,
                visit.range(word.value_range.unwrap_or(word.range)),
                format!("in a thread block E is the lead-in length, which the control takes only with a decimal point: write `E{lead_in}.`"),
            ));
        }
        if spindle_stopped(visit.after) {
            out.push(Diagnostic::new(
                &SPINDLE_NOT_RUNNING,
                head,
                "G33 couples the axis to the spindle, but the spindle is stopped (M05); start it with M03 or M04 and S",
            ));
        }
        if block.word(b'J').is_some() || block.word(b'E').is_some() {
            self.after = After::EmptyBlock;
        }
    }
}

fn spindle_stopped(state: &ModalState) -> bool {
    state.m(2) == Some(Some(5))
}

/// The block after the empty block programs every axis of the machine
/// (the spindle axis C excepted), repeating positions that do not change.
fn check_all_axes(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    let block: &BlockData = visit.block;
    let missing: Vec<char> = visit
        .config
        .machine
        .axes
        .iter()
        .copied()
        .filter(|&axis| axis != b'C' && block.word(axis).is_none())
        .map(char::from)
        .collect();
    if !missing.is_empty() {
        let head = block.words.first().map_or(visit.range(Default::default()), |w| visit.range(w.range));
        let list: Vec<String> = missing.iter().map(char::to_string).collect();
        out.push(Diagnostic::new(
            &THREAD_EXIT_MISSING_AXES,
            head,
            format!(
                "after a thread's empty block every axis must be programmed, even where it does not move: add {}",
                list.join(", ")
            ),
        ));
    }
}
