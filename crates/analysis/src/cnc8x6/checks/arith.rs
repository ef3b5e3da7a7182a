//! Parameter arithmetic G26–G29: the control words and what they do with
//! their operands; and parameter values whose reader expects a unit or an
//! encoding: dimensionless addresses, fixed-cycle inputs, and the thread
//! run-out and lead-in angles that machine constant 8 names.
//!
//! A control word's own faults (operation code, fields, sign, ranges) are
//! found by running the word alone with every parameter unknown, so the
//! evaluator of `nc_exec` stays the one place that knows the operations.
//! Failures of the values (division by zero, overflow, …) are
//! `arithmetic-error`'s.

use nc_exec::cnc8x6::arith::{self, ArithConfig, ArithError, ControlWord, Parameters, Raw, UnknownMachine};
use ncc_catalog::{AddressRole, Dialect};
use ncc_syntax::{Severity, TextEdit, TextRange};
use rustc_hash::FxHashSet;

use crate::{
    Diagnostic, Rule,
    cnc8x6::checks::{
        block::{self, parameter_raw},
        params,
    },
    cnc8x6::flow::{FlowCheck, Origin, Visit},
    diagnostic::declare_rules,
    lower::{Value, Word},
};

declare_rules! {
    INVALID_CONTROL_WORD_FORMAT = "A501", "invalid-control-word-format", Warning, "A control word in R5–R8 written with a decimal point.";
    UNDEFINED_OPERATION_CODE = "A502", "undefined-operation-code", Error, "A control word with operation code 43 or 52–99.";
    OPERAND_FIELD_OUT_OF_RANGE = "A503", "operand-field-out-of-range", Error, "An operand or target field that names no parameter without double precision (96–99).";
    DOUBLE_PRECISION_NOT_ALLOWED = "A504", "double-precision-not-allowed", Error, "A double-precision pair in a field where the operation takes a single parameter.";
    INTEGER_MODE_NOT_ALLOWED = "A505", "integer-mode-not-allowed", Error, "Operation 11, 12, 13, 27 or 28 written with the `-` (integer) sign.";
    SHIFT_COUNT_OUT_OF_RANGE = "A506", "shift-count-out-of-range", Error, "A binary shift (operation 09) by more than 32 places (64 with a pair).";
    PROGRAM_OP_NOT_LAST = "A507", "program-op-not-last", Error, "PROGRAM (operation 33) followed by another operation.";
    INVALID_PROGRAM_OP_RANGE = "A508", "invalid-program-op-range", Warning, "PROGRAM (operation 33) with a reversed range or a range holding no control words.";
    INVALID_PARAMETER_BLOCK_RANGE = "A509", "invalid-parameter-block-range", Error, "A parameter range of operation 34, 35 or 45 that is reversed, overlaps or leaves R0–R95.";
    REAL_INCREMENT_ON_INTEGER_PARAMETER = "A510", "real-increment-on-integer-parameter", Warning, "Increment or decrement (operation 41, 42) in real mode of a parameter declared as an integer.";
    INVALID_CONTROL_WORD_FIELD = "A511", "invalid-control-word-field", Error, "A field of operation 25, 26 or 48–51 outside its range.";
    UNTERMINATED_CONDITION = "A512", "unterminated-condition", Warning, "A condition (operation 20, 21, 29–32) with no end of condition (operation 22) after it.";
    PARAMETER_UNIT_MISMATCH = "A513", "parameter-unit-mismatch", Warning, "A parameter written with or without a decimal point against the unit its reader expects.";
    THREAD_ANGLE_OUT_OF_RANGE = "A514", "thread-angle-out-of-range", Error, "A thread run-out or lead-in angle parameter outside 0–60°.";
    THREAD_ANGLE_MISSING_AXIS = "A515", "thread-angle-missing-axis", Warning, "A thread angle parameter without the axis ordinal in its hundreds digit.";
    THREAD_ANGLE_MISMATCH = "A516", "thread-angle-mismatch", Warning, "Lead-in and run-out angle parameters that differ in axis or sign.";
}

/// Operation codes with a role in the sequence of a block's words (the
/// evaluator's reading of chapter 11).
const SHIFT: u8 = 9;
const END_OF_CONDITION: u8 = 22;
const PROGRAM: u8 = 33;
const INCREMENT: u8 = 41;
const DECREMENT: u8 = 42;

/// The conditions: when one fails, the words after it are skipped up to
/// operation 22.
fn is_condition(op: u8) -> bool {
    matches!(op, 20 | 21 | 29..=32)
}

#[derive(Default)]
pub(crate) struct Arithmetic {
    /// Findings already made about an assigned value (rule code, the
    /// assignment): a cycle runs at every hole and a thread at every pass,
    /// but one report per assignment is enough.
    reported: FxHashSet<(&'static str, TextRange)>,
}

impl FlowCheck for Arithmetic {
    fn block(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        if let Some((code, word)) = visit.block.codes(b'G').find(|(code, _)| (26..=29).contains(code)) {
            check_control_words_set(visit, code, word, out);
            let run = Run::new(visit, code, word);
            run.check_format(out);
            run.check_words(out);
            run.check_sequence(out);
            run.check_failure(out);
        }
        check_dimensionless_units(visit, out);
        self.check_cycle_inputs(visit, out);
        self.check_thread_angles(visit, out);
    }
}

/// Whether an arithmetic failure belongs to one of this module's rules; the
/// rest, failures of the values, are `arithmetic-error`'s.
pub(crate) fn has_own_rule(error: &ArithError) -> bool {
    match error {
        ArithError::InProgram { error, .. } => has_own_rule(error),
        _ => rule_for(0, error).is_some(),
    }
}

/// The rule for a failure that a word of operation `op` causes whatever its
/// operands hold (`None`: a failure of the values).
fn rule_for(op: u8, error: &ArithError) -> Option<&'static Rule> {
    use ArithError as E;
    Some(match error {
        E::ControlWordTooLong(_) => &INVALID_CONTROL_WORD_FORMAT,
        E::UndefinedOperation(_) => &UNDEFINED_OPERATION_CODE,
        E::DoublePrecisionNotAllowed { .. } => &DOUBLE_PRECISION_NOT_ALLOWED,
        E::IntegerModeNotAllowed(_) => &INTEGER_MODE_NOT_ALLOWED,
        E::ShiftOutOfRange { .. } => &SHIFT_COUNT_OUT_OF_RANGE,
        E::OperationAfterProgram => &PROGRAM_OP_NOT_LAST,
        E::InvalidRange { .. } | E::FieldOutOfRange { .. } if op == PROGRAM => &INVALID_PROGRAM_OP_RANGE,
        E::InvalidRange { .. } | E::RangePastEnd | E::OverlappingRanges => &INVALID_PARAMETER_BLOCK_RANGE,
        E::FieldOutOfRange { .. } if matches!(op, 34 | 35 | 45) => &INVALID_PARAMETER_BLOCK_RANGE,
        // Ops 25 and 26 hold axis numbers in op1 and op2; ops 48–51 are re-encoded.
        E::FieldOutOfRange { field, .. } if op >= 48 || (matches!(op, 25 | 26) && *field != "target") => {
            &INVALID_CONTROL_WORD_FIELD
        }
        E::FieldOutOfRange { .. } => &OPERAND_FIELD_OUT_OF_RANGE,
        _ => return None,
    })
}

/// What a word fails with on its own, whatever the parameters hold: the word
/// run alone with every parameter unknown. With the double-precision mode
/// unknown, only a failure of the same rule in both modes counts.
fn static_error(word: ControlWord, double_precision: Option<bool>) -> Option<(ArithError, &'static Rule)> {
    let modes: &[bool] = match double_precision {
        Some(mode) => &[mode][..],
        None => &[false, true],
    };
    let mut found: Option<(ArithError, &'static Rule)> = None;
    for &double_precision in modes {
        let config = ArithConfig { double_precision };
        let (_, error) = arith::execute(&[word], &mut Parameters::unknown(), &mut UnknownMachine, config).err()?;
        let rule = rule_for(word.op, &error)?;
        if found.as_ref().is_some_and(|(_, first)| *first != rule) {
            return None;
        }
        found.get_or_insert((error, rule));
    }
    found
}

/// A control word the block runs, and where its value comes from.
#[derive(Clone, Copy)]
struct Source {
    /// The parameter that holds it.
    parameter: usize,
    raw: Raw,
    word: ControlWord,
    origin: Option<Origin>,
}

impl Source {
    fn place(&self) -> (usize, Option<Origin>) {
        (self.parameter, self.origin)
    }
}

/// The arithmetic of one G26–G29 block.
struct Run<'v, 'a> {
    visit: &'v Visit<'a>,
    /// The G26–G29 word.
    at: TextRange,
    /// The control words in R5, R6, … (`None`: not known).
    words: Vec<Option<Source>>,
    double_precision: Option<bool>,
}

impl<'v, 'a> Run<'v, 'a> {
    fn new(visit: &'v Visit<'a>, code: u32, word: &Word) -> Self {
        let words = (5..5 + (code as usize - 25))
            .map(|parameter| {
                let (raw, origin) = value_at_start(visit, parameter)?;
                // A value within the parameter range always decodes.
                let word = ControlWord::decode(raw).ok()?;
                Some(Source { parameter, raw, word, origin })
            })
            .collect();
        let r95 = value_at_start(visit, 95).map(|(raw, _)| raw);
        Run { visit, at: visit.range(word.range), words, double_precision: visit.config.machine.double_precision(r95) }
    }

    /// R5–R8 literals with a decimal point: the control stores them in
    /// thousandths, so the digits no longer match the fields.
    fn check_format(&self, out: &mut Vec<Diagnostic>) {
        let slots = 5..5 + self.words.len() as u32;
        for assignment in &self.visit.block.assignments {
            let Some(index) = assignment.index.filter(|i| slots.contains(i)) else { continue };
            let Some(Value::Literal(value)) = &assignment.value else { continue };
            if !value.has_point() {
                continue;
            }
            let range = self.visit.range(assignment.value_range.unwrap_or(assignment.range));
            let stored = parameter_raw(value).filter(|raw| raw.abs() <= arith::MAX_RAW);
            let explanation = match stored {
                Some(raw) => format!(
                    "`{value}` is stored as {raw} thousandths and runs as the control word `{}`",
                    show_word(raw)
                ),
                None => format!("`{value}` does not even fit a parameter"),
            };
            let mut diagnostic = Diagnostic::new(
                &INVALID_CONTROL_WORD_FORMAT,
                range,
                format!(
                    "the control word in R{index} is written with a decimal point, but a control word is an integer of up to 8 digits (`±CCAABBTT`): {explanation}; write the digits without the point"
                ),
            );
            // With three decimals the thousandths are the written digits, so
            // dropping the point keeps the word that runs.
            if value.frac_digits() == 3 && stored.is_some() {
                let digits = value.to_string().replace('.', "");
                diagnostic = diagnostic.with_fix(
                    "Write the control word without the decimal point",
                    vec![TextEdit::replace(range, digits)],
                );
            }
            out.push(diagnostic);
        }
    }

    /// Each word's own faults: operation code, fields, sign, ranges.
    fn check_words(&self, out: &mut Vec<Diagnostic>) {
        for source in self.words.iter().flatten() {
            let Some((error, rule)) = static_error(source.word, self.double_precision) else { continue };
            let mut diagnostic = located(self.visit, rule, source.place(), self.at, explain(rule, source, &error));
            let range = diagnostic.range;
            if matches!(error, ArithError::IntegerModeNotAllowed(_)) && source.origin.is_some_and(|o| o.range == range)
            {
                diagnostic = diagnostic.with_fix(
                    "Write the control word without the `-` sign (real mode)",
                    vec![TextEdit::replace(range, show_word(source.raw.abs()))],
                );
            }
            out.push(diagnostic);
        }
    }

    /// The words in their order: PROGRAM last, conditions ended, increments
    /// in the mode of their parameter.
    fn check_sequence(&self, out: &mut Vec<Diagnostic>) {
        for (i, source) in self.words.iter().enumerate() {
            let Some(source) = source else { continue };
            let later = &self.words[i + 1..];
            match source.word.op {
                PROGRAM => {
                    if let Some(next) = later.first() {
                        self.report_program_not_last(source, 5 + i + 1, next.as_ref(), out);
                    }
                    if static_error(source.word, self.double_precision).is_none() {
                        self.check_program_range(i, source, out);
                    }
                }
                op if is_condition(op) => {
                    let ended = later.iter().flatten().any(|s| matches!(s.word.op, END_OF_CONDITION | PROGRAM));
                    // An unknown later word may be the end of the condition.
                    if !ended && later.iter().all(Option::is_some) {
                        let word = show_word(source.raw);
                        let message = if later.is_empty() {
                            format!(
                                "the condition `{word}` ({}) is the block's last operation, so it guards nothing; put the operations it guards after it and end them with `22000000`",
                                title(op)
                            )
                        } else {
                            format!(
                                "the condition `{word}` ({}) has no end of condition after it: when it fails, the control skips every later operation of the block; end the operations it guards with `22000000`",
                                title(op)
                            )
                        };
                        out.push(located(self.visit, &UNTERMINATED_CONDITION, source.place(), self.at, message));
                    }
                }
                INCREMENT | DECREMENT if !source.word.integer => self.check_increment(i, source, out),
                _ => {}
            }
        }
    }

    fn report_program_not_last(
        &self,
        source: &Source,
        next: usize,
        next_word: Option<&Source>,
        out: &mut Vec<Diagnostic>,
    ) {
        let code = 25 + self.words.len();
        let message = format!(
            "PROGRAM (operation 33) must be the block's last operation, but G{code} runs R{next} after it, so the control stops with an error; make PROGRAM the last control word, or move R{next}'s operation into the program"
        );
        let mut diagnostic = located(self.visit, &PROGRAM_OP_NOT_LAST, source.place(), self.at, message);
        if let Some(origin) = next_word.and_then(|w| w.origin).filter(|o| !o.computed) {
            diagnostic = diagnostic.with_related(None, origin.range, format!("R{next} follows it here"));
        }
        out.push(diagnostic);
    }

    /// The parameters a PROGRAM runs should hold control words: not values
    /// written with a decimal point, and not parameters never assigned.
    fn check_program_range(&self, i: usize, source: &Source, out: &mut Vec<Diagnostic>) {
        let params = self.visit.params;
        for n in usize::from(source.word.op1)..=usize::from(source.word.target) {
            // An earlier word of the block may fill the parameter.
            if self.words[..i].iter().any(|w| w.is_none_or(|w| may_write(&w.word, n))) {
                continue;
            }
            let word = show_word(source.raw);
            let problem = match value_at_start(self.visit, n) {
                Some((raw, Some(origin))) if origin.point && !origin.computed => Some((
                    format!(
                        "PROGRAM `{word}` runs R{n:02}, which holds {}, a number written with a decimal point rather than a control word; write control words as integers (`±CCAABBTT`)",
                        params::show(raw)
                    ),
                    Some(origin),
                )),
                None if params.from_start
                    && params.origins.get(n).is_some_and(Option::is_none)
                    && !self.visit.block.assignments.iter().any(|a| a.index == Some(n as u32)) =>
                {
                    Some((
                        format!(
                            "PROGRAM `{word}` runs R{n:02}, which the program never assigns, so it runs whatever an earlier program left there; assign R{n:02} a control word before (or in) this block"
                        ),
                        None,
                    ))
                }
                _ => None,
            };
            let Some((message, origin)) = problem else { continue };
            let diagnostic = located(self.visit, &INVALID_PROGRAM_OP_RANGE, source.place(), self.at, message);
            out.push(with_assignment(diagnostic, n, origin));
        }
    }

    /// Operation 41/42 in real mode adds whole units to a parameter that was
    /// declared as an integer (in thousandths).
    fn check_increment(&self, i: usize, source: &Source, out: &mut Vec<Diagnostic>) {
        let word = source.word;
        let n = usize::from(word.op1);
        // A field of 50 or more may name a double-precision pair.
        if n >= 50 && self.double_precision != Some(false) {
            return;
        }
        if self.words[..i].iter().any(|w| w.is_none_or(|w| may_write(&w.word, n))) {
            return;
        }
        let Some((value, Some(origin))) = value_at_start(self.visit, n) else { return };
        if origin.point || origin.computed || value == 0 {
            return;
        }
        let step = Raw::from(if word.op2 == 0 { 1 } else { word.op2 });
        let (verb, sign) = if word.op == INCREMENT { ("adds", 1) } else { ("subtracts", -1) };
        let message = format!(
            "`{}` {verb} {step} in real mode, but R{n:02} was declared as the integer {value} (without a decimal point it holds {}), so the result is {} instead of {}; write the control word with `-` to count in whole numbers",
            show_word(source.raw),
            params::show(value),
            params::show(value + sign * step * 1000),
            value + sign * step,
        );
        let located = located(self.visit, &REAL_INCREMENT_ON_INTEGER_PARAMETER, source.place(), self.at, message);
        let mut diagnostic = with_assignment(located, n, Some(origin));
        let range = diagnostic.range;
        if source.origin.is_some_and(|o| o.range == range) {
            diagnostic = diagnostic.with_fix(
                "Write the control word with `-` (integer mode)",
                vec![TextEdit::replace(range, show_word(-source.raw))],
            );
        }
        out.push(diagnostic);
    }

    /// Failures the control words cause with the values they meet: a shift
    /// count out of range, and faults of the words a PROGRAM runs.
    fn check_failure(&self, out: &mut Vec<Diagnostic>) {
        // With the mode unknown the walk ran the words without double
        // precision, so a failure may be that assumption's.
        let Some((_, error)) = self.visit.arithmetic_error.filter(|_| self.double_precision.is_some()) else { return };
        match error {
            ArithError::ShiftOutOfRange { count, limit } => {
                // The word that failed: the block's shift, if it has only one.
                let shifts: Vec<&Source> = self.words.iter().flatten().filter(|s| s.word.op == SHIFT).collect();
                let only = match shifts.as_slice() {
                    [source] => Some(*source),
                    _ => None,
                };
                out.push(shift_finding(self.visit, only, (*count, *limit), self.at, ""));
            }
            ArithError::InProgram { parameter, error } => {
                let parameter = usize::from(*parameter);
                // The failing word is still in its parameter: words fail before they store.
                let Some((raw, origin)) = self.visit.params_after.get(parameter as u32) else { return };
                let context = format!("PROGRAM runs R{parameter:02}: ");
                let Ok(word) = ControlWord::decode(raw) else {
                    let message =
                        format!("{context}it holds {raw}, which has more than 8 digits and is no control word");
                    out.push(located(self.visit, &INVALID_PROGRAM_OP_RANGE, (parameter, origin), self.at, message));
                    return;
                };
                let source = Source { parameter, raw, word, origin };
                if let ArithError::ShiftOutOfRange { count, limit } = error.as_ref() {
                    out.push(shift_finding(self.visit, Some(&source), (*count, *limit), self.at, &context));
                } else if let Some(rule) = rule_for(word.op, error) {
                    let message = format!("{context}{}", explain(rule, &source, error));
                    out.push(located(self.visit, rule, source.place(), self.at, message));
                }
            }
            _ => {}
        }
    }
}

/// R`n` when the block's arithmetic starts: after the block's own
/// assignments, which the arithmetic sees.
/// G26–G29 run the control words R5, R6, … hold: written in the block, or
/// left there by an earlier block (the manual's cycles compute a "modified
/// instruction" into R7 and leave it out of the G29 block). Only a control
/// word the program never assigned is missing.
fn check_control_words_set(visit: &Visit<'_>, code: u32, word: &Word, out: &mut Vec<Diagnostic>) {
    if !visit.params.from_start {
        return;
    }
    let last = 4 + code - 25;
    let missing: Vec<String> = (5..=last)
        .filter(|&n| visit.block.assignments.iter().all(|a| a.index != Some(n)))
        .filter(|&n| visit.params.origins.get(n as usize).is_some_and(Option::is_none))
        .map(|n| format!("R{n}"))
        .collect();
    if !missing.is_empty() {
        out.push(Diagnostic::new(
            &block::MISSING_REQUIRED_ADDRESS,
            visit.range(word.range),
            format!(
                "G{code} runs the control words in R5 to R{last}, but the program has not assigned {}, so the control runs whatever an earlier program left there; write `{}=…` with its control word in this block",
                missing.join(", "),
                missing[0]
            ),
        ));
    }
}

fn value_at_start(visit: &Visit<'_>, n: usize) -> Option<(Raw, Option<Origin>)> {
    let assignment = visit.block.assignments.iter().rev().find(|a| a.index == Some(n as u32));
    let Some(assignment) = assignment else { return visit.params.get(n as u32) };
    let Some(Value::Literal(value)) = &assignment.value else { return None };
    let raw = parameter_raw(value).filter(|raw| raw.abs() <= arith::MAX_RAW)?;
    let range = visit.range(assignment.value_range.unwrap_or(assignment.range));
    Some((raw, Some(Origin { range, point: value.has_point(), computed: false })))
}

/// Whether `word` may store into R`n` (ranges and programs anywhere; the
/// target field also as half of a pair).
fn may_write(word: &ControlWord, n: usize) -> bool {
    let target = usize::from(word.target);
    matches!(word.op, 33..=35 | 45) || target == n || (target >= 50 && (target - 50 == n || target - 49 == n))
}

/// A finding about the value of R`parameter`: at its literal when this
/// block assigns it, else at `at` with the assignment as related location.
fn located(
    visit: &Visit<'_>,
    rule: &'static Rule,
    (parameter, origin): (usize, Option<Origin>),
    at: TextRange,
    message: String,
) -> Diagnostic {
    let block = TextRange::at(visit.offset, visit.block.len);
    match origin {
        Some(origin) if !origin.computed && block.contains_range(origin.range) => {
            Diagnostic::new(rule, origin.range, message)
        }
        Some(origin) if origin.range != at => {
            with_assignment(Diagnostic::new(rule, at, message), parameter, Some(origin))
        }
        _ => Diagnostic::new(rule, at, message),
    }
}

/// `diagnostic` with the place where R`parameter` got its value.
fn with_assignment(diagnostic: Diagnostic, parameter: impl std::fmt::Display, origin: Option<Origin>) -> Diagnostic {
    match origin {
        Some(origin) => {
            let how = if origin.computed { "computed" } else { "assigned" };
            diagnostic.with_related(None, origin.range, format!("R{parameter:0>2} was {how} here"))
        }
        None => diagnostic,
    }
}

/// What is wrong with a word, for a programmer.
fn explain(rule: &'static Rule, source: &Source, error: &ArithError) -> String {
    let word = source.word;
    let (text, op, title) = (show_word(source.raw), word.op, title(word.op));
    match error {
        ArithError::UndefinedOperation(_) => format!(
            "`{text}`: operation {op:02} does not exist (the codes are 00–42 and 44–51), so the control stops with an error here; check decades 8–7 of the word"
        ),
        ArithError::FieldOutOfRange { field, value } if *rule == OPERAND_FIELD_OUT_OF_RANGE => format!(
            "`{text}` ({title}): the {field} field holds {value}, but without double precision (machine constant 283 decade 4, or decade 1 of R95) the fields name only R00 to R95; name a parameter up to R95"
        ),
        ArithError::DoublePrecisionNotAllowed { field, .. } => {
            let value = match *field {
                "op1" => word.op1,
                "op2" => word.op2,
                _ => word.target,
            };
            format!(
                "`{text}` ({title}): with double precision on, the {field} field {value} names the pair R{:02}/R{:02}, but operation {op:02} takes a single parameter there; name one of R00 to R49",
                value.saturating_sub(50),
                value.saturating_sub(49)
            )
        }
        ArithError::IntegerModeNotAllowed(_) => format!(
            "`{text}` ({title}): the `-` sign selects integer mode, but operation {op:02} works only with real values, so the control rejects the word; write it without the sign"
        ),
        _ if *rule == INVALID_PROGRAM_OP_RANGE => format!(
            "`{text}` ({title}): {error}; PROGRAM runs the control words from the parameter in decades 6–5 to the one in decades 2–1"
        ),
        _ if *rule == INVALID_PARAMETER_BLOCK_RANGE => {
            format!("`{text}` ({title}): {error}; the ranges must lie within R00 to R95")
        }
        _ if *rule == INVALID_CONTROL_WORD_FIELD => {
            let layout = Dialect::Cnc8x6.catalogue().operation(u32::from(op)).map_or("", |o| o.operands.as_str());
            format!("`{text}` ({title}): {error} (the fields: {layout})")
        }
        _ => format!("`{text}` ({title}): {error}"),
    }
}

/// A shift count out of range, with the likely cause: a count written with
/// a decimal point is a thousand times too large.
fn shift_finding(
    visit: &Visit<'_>,
    source: Option<&Source>,
    (count, limit): (Raw, u8),
    at: TextRange,
    context: &str,
) -> Diagnostic {
    let Some(source) = source else {
        let message = format!(
            "{context}a binary shift (operation 09) by {count} places is beyond ±{limit}, so the control stops with an error"
        );
        return Diagnostic::new(&SHIFT_COUNT_OUT_OF_RANGE, at, message);
    };
    let n = source.word.op2;
    let mut message = format!(
        "{context}the binary shift `{}` moves R{:02} by R{n:02} = {count} places, beyond ±{limit}: operation 09 reads the count as a whole number",
        show_word(source.raw),
        source.word.op1
    );
    let count_origin = visit.params_after.get(u32::from(n)).and_then(|(_, origin)| origin);
    if count_origin.is_some_and(|o| o.point && !o.computed) && count % 1000 == 0 {
        message.push_str(&format!(
            "; R{n:02} was written with a decimal point, so it holds {count}: write R{n:02}={} without the point",
            count / 1000
        ));
    }
    let diagnostic = located(visit, &SHIFT_COUNT_OUT_OF_RANGE, source.place(), at, message);
    with_assignment(diagnostic, n, count_origin)
}

/// A control word as the manual writes it: sign and eight digits.
fn show_word(raw: Raw) -> String {
    let sign = if raw < 0 { "-" } else { "" };
    format!("{sign}{:08}", raw.unsigned_abs())
}

fn title(op: u8) -> &'static str {
    Dialect::Cnc8x6.catalogue().operation(u32::from(op)).map_or("undefined", |o| o.title.as_str())
}

/// A dimensionless address (S, T, Q, …) reads a parameter's raw
/// thousandths: one written with a decimal point (`R20=12.`) gives a
/// thousand times the number (T12000). Lengths and feed have rules of their
/// own; where the digits do not fit the address, the substitution check
/// reports it.
fn check_dimensionless_units(visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
    let catalogue = Dialect::Cnc8x6.catalogue();
    for (word, substitution) in visit.block.words.iter().zip(visit.substitutions) {
        let (Some(substitution), Some(Value::Parameter { index: Some(index), .. })) = (substitution, &word.value)
        else {
            continue;
        };
        let Some(origin) = substitution.origin.filter(|o| o.point && !o.computed) else { continue };
        let Some(address) = std::str::from_utf8(&[word.letter]).ok().and_then(|letter| catalogue.address(letter))
        else {
            continue;
        };
        let raw = substitution.raw;
        // A fraction (`R20=0.120` for S120) is how the digits are meant.
        if address.frac_digits != Some(0) || address.role == AddressRole::Feed || raw == 0 || raw % 1000 != 0 {
            continue;
        }
        let mut substitution_findings = Vec::new();
        params::check_substitution(visit, word, *substitution, &mut substitution_findings);
        if !substitution_findings.is_empty() {
            continue;
        }
        let letter = &address.letter;
        let found = Diagnostic::new(
            &PARAMETER_UNIT_MISMATCH,
            visit.range(word.value_range.unwrap_or(word.range)),
            format!(
                "R{index} was written with a decimal point, so `{letter}` reads its thousandths: {letter}{raw}, not {letter}{}; write R{index}={} without the point",
                raw / 1000,
                raw / 1000
            ),
        );
        // The manual only recommends the form here (rule 75): a hint.
        let mut diagnostic = with_assignment(found, index, Some(origin));
        diagnostic.severity = Severity::Info;
        out.push(diagnostic);
    }
}

impl Arithmetic {
    /// A fixed cycle reads its plane and length inputs in mm: one written
    /// without a decimal point is in thousandths (`R30=5` is 0.005 mm).
    /// Checked only for inputs that every cycle file with this code reads as
    /// a length, as the configuration does not say which file is loaded.
    fn check_cycle_inputs(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        let Some(Some(code @ 81..=89)) = visit.after.g(8) else { return };
        let cycles: Vec<_> = Dialect::Cnc8x6.catalogue().cycles_for(&format!("G{code}")).collect();
        let Some(first) = cycles.first() else { return };
        let is_length =
            |r: u32| cycles.iter().all(|c| c.parameters.iter().any(|p| p.r == r && p.unit.as_deref() == Some("mm")));
        for input in first.parameters.iter().filter(|p| is_length(p.r)) {
            let Some((raw, Some(origin))) = visit.params_after.get(input.r) else { continue };
            if origin.point
                || origin.computed
                || raw == 0
                || !self.reported.insert((PARAMETER_UNIT_MISMATCH.code, origin.range))
            {
                continue;
            }
            let reader =
                visit.code_range(b'G', code).or_else(|| visit.block.words.first().map(|w| visit.range(w.range)));
            let r = input.r;
            let found = Diagnostic::new(
                &PARAMETER_UNIT_MISMATCH,
                reader.unwrap_or(TextRange::empty(visit.offset)),
                format!(
                    "G{code} reads R{r} as a length in mm, but R{r} was written without a decimal point, so it holds {} mm; write R{r}={raw}. for {raw} mm",
                    params::show(raw)
                ),
            );
            out.push(with_assignment(found, r, Some(origin)));
        }
    }

    /// Machine constant 8 may name the parameters that hold a thread's
    /// run-out angle (decades 8–7) and lead-in angle (decades 6–5), each
    /// `±A XX.XXX`: the axis ordinal in the hundreds digit and the angle in
    /// degrees. The thread reads them where J (run-out) or E (lead-in) is
    /// written. Machine constant 8 with decades 8–7 at 0 holds the angle
    /// itself, which is the configuration's business.
    fn check_thread_angles(&mut self, visit: &Visit<'_>, out: &mut Vec<Diagnostic>) {
        if visit.after.g(0) != Some(Some(33)) {
            return;
        }
        let constant = visit.config.machine.constant(8).unsigned_abs();
        let (runout, leadin) = ((constant / 1_000_000 % 100) as u32, (constant / 10_000 % 100) as u32);
        if runout == 0 {
            return;
        }
        let angle = |parameter: u32| {
            let (raw, origin) = visit.params_after.get(parameter)?;
            Some(Angle { parameter, raw, origin })
        };
        if let (Some(j), Some(run)) = (visit.block.word(b'J'), angle(runout)) {
            self.check_angle(visit, j, "run-out", &run, out);
        }
        let Some(e) = visit.block.word(b'E').filter(|_| leadin != 0) else { return };
        let Some(lead) = angle(leadin) else { return };
        self.check_angle(visit, e, "lead-in", &lead, out);
        let Some(run) = angle(runout).filter(|run| run.parameter != lead.parameter) else { return };
        let differs = match (run.axis() != lead.axis(), (run.raw < 0) != (lead.raw < 0)) {
            (true, true) => "axis and sign",
            (true, false) => "axis",
            (false, true) => "sign",
            (false, false) => return,
        };
        if !self.first_report(&THREAD_ANGLE_MISMATCH, &lead, visit.range(e.range)) {
            return;
        }
        let found = Diagnostic::new(
            &THREAD_ANGLE_MISMATCH,
            visit.range(e.range),
            format!(
                "the lead-in angle R{:02} = {} and the run-out angle R{:02} = {} differ in {differs}: both must name the same axis and carry the same sign (the run-out decides; the control reverses the lead-in itself)",
                lead.parameter,
                params::show(lead.raw),
                run.parameter,
                params::show(run.raw)
            ),
        );
        out.push(with_assignment(with_assignment(found, lead.parameter, lead.origin), run.parameter, run.origin));
    }

    fn check_angle(&mut self, visit: &Visit<'_>, reader: &Word, what: &str, angle: &Angle, out: &mut Vec<Diagnostic>) {
        let range = visit.range(reader.range);
        let (parameter, value) = (angle.parameter, params::show(angle.raw));
        let degrees = angle.raw.unsigned_abs() % 100_000;
        let mut found: Vec<(&'static Rule, String)> = Vec::new();
        if degrees > 60_000 {
            found.push((
                &THREAD_ANGLE_OUT_OF_RANGE,
                format!(
                    "R{parameter:02} holds the {what} angle of this thread (machine constant 8): {value} is {}° on axis {}, but the angle must be 0 to 60°",
                    params::show(degrees as Raw),
                    angle.axis()
                ),
            ));
        }
        if angle.axis() == 0 && angle.raw != 0 {
            let sign = if angle.raw < 0 { "-" } else { "" };
            found.push((
                &THREAD_ANGLE_MISSING_AXIS,
                format!(
                    "R{parameter:02} holds the {what} angle of this thread (machine constant 8), but {value} has no axis ordinal in its hundreds digit, so the control does not know which axis it concerns; write e.g. R{parameter:02}={sign}{} for axis 1 (X)",
                    params::show(100_000 + degrees as Raw)
                ),
            ));
        }
        for (rule, message) in found {
            if self.first_report(rule, angle, range) {
                out.push(with_assignment(Diagnostic::new(rule, range, message), parameter, angle.origin));
            }
        }
    }

    /// Whether this is the first finding of `rule` about the value's assignment.
    fn first_report(&mut self, rule: &'static Rule, angle: &Angle, reader: TextRange) -> bool {
        self.reported.insert((rule.code, angle.origin.map_or(reader, |o| o.range)))
    }
}

/// A thread angle parameter and its value.
struct Angle {
    parameter: u32,
    raw: Raw,
    origin: Option<Origin>,
}

impl Angle {
    /// The axis ordinal: the hundreds digit of the value.
    fn axis(&self) -> u64 {
        self.raw.unsigned_abs() / 100_000 % 10
    }
}

#[cfg(test)]
mod tests {
    use crate::AnalysisHost;

    /// The program after the first fix of the first diagnostic of `rule`,
    /// and what the fixed program reports.
    fn fixed(text: &str, rule: &str) -> (String, Vec<&'static str>) {
        let check = |text: &str| {
            let mut host = AnalysisHost::default();
            let file = host.add_file("main.NCP", text);
            host.analysis().diagnostics(file)
        };
        let diagnostics = check(text);
        let diagnostic =
            diagnostics.iter().find(|d| d.name == rule).unwrap_or_else(|| panic!("{rule}: {diagnostics:#?}"));
        let mut result = text.to_owned();
        for edit in &diagnostic.fixes[0].edits {
            edit.apply(&mut result);
        }
        let names = check(&result).iter().map(|d| d.name).collect();
        (result, names)
    }

    #[test]
    fn fixes_keep_the_word_and_resolve_the_finding() {
        let cases = [
            ("N20 G26 R5=19141.706\n", "invalid-control-word-format", "N20 G26 R5=19141706\n"),
            ("N20 G26 R5=-11100010\n", "integer-mode-not-allowed", "N20 G26 R5=11100010\n"),
            (
                "N10 R12=4\nN20 G26 R5=+42120212\n",
                "real-increment-on-integer-parameter",
                "N10 R12=4\nN20 G26 R5=-42120212\n",
            ),
        ];
        for (body, rule, fixed_body) in cases {
            let (result, remaining) = fixed(&format!("%1\n{body}N90 M30\n*\n"), rule);
            assert_eq!(result, format!("%1\n{fixed_body}N90 M30\n*\n"));
            assert!(remaining.is_empty(), "{rule}: {remaining:?}");
        }
    }
}
