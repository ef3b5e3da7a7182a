//! Parameter arithmetic: the control words of G26–G29 (chapter 11 of the
//! CNC8x6 programming manual; the catalogue's `operations.toml` holds the
//! project's reading of every operation).
//!
//! A control word `±CCAABBTT` names an operation (`CC`), two operands (`AA`,
//! `BB`) and a target (`TT`). The sign chooses the mode: `+` (or none) works on
//! real values (the raw thousandths / 1000) and rounds every result to a
//! thousandth, `-` works on the raw integers.
//!
//! The evaluator serves both the static analysis and the executor: a
//! parameter may be unknown (`None`), and an operation with an unknown
//! operand makes its target unknown instead of failing.
//!
//! Readings of the manual's gaps that this module takes (each is the project's
//! decision, not the manual's text):
//! - Real results are rounded to a thousandth, halves away from zero. Integer
//!   results drop the fraction (toward zero), as integer division does: ops 4,
//!   6, 10 and 14 in integer mode, and op 24 (real → integer). Op 9 shifts the
//!   binary value, so a right shift rounds toward minus infinity; its count is
//!   the raw integer of op2 in both modes (the lathe cycles' `R32=-1`).
//! - Comparisons, parity and TEST store raw 73 or 78 in both modes, so that
//!   `GRxx` yields G73 (jump) or G78 (no-op). Parity is that of the raw integer.
//! - Op 48 works on the decimal digits of the raw magnitude (the sign stays);
//!   NOT, OR, AND and XOR treat a digit as a bit (0, or not 0), and TEST gives
//!   73 when the digit is not 0.
//! - A double-precision pair (field 50–99 with double precision on) holds one
//!   64-bit raw value in two's complement: the low 32 bits in the first
//!   parameter, the high 32 bits in the second, each read as a signed 32-bit
//!   number. A value that fits in 32 bits therefore reads back unchanged from
//!   the first parameter. Exception, from the supplied lathe cycles: ops 25 and
//!   26 put the positions of axes op1 and op2 into the two parameters (with a
//!   single target, op2 is not used).
//! - Double precision applies to the operand and target fields of the ordinary
//!   operations. The parameter fields of ops 33–35, 44, 45 and 48–51 always
//!   name R0–R95 directly (`48110095` must reach R95 with double precision on);
//!   axis numbers (25, 26) and the immediate of 41/42 are numbers. A pair where
//!   the manual forbids one (op1 of 11 and 27, op1 and op2 of 13 and 28, the
//!   target of 12) is an error; where only the label lacks the `*`, the pair is
//!   read (the analysis warns).
//! - Angles are in degrees, as elsewhere on the control (the manual states no
//!   unit). Ops 37/38 store round(sin · 10 000 000) as a raw integer in both
//!   modes; the angle is raw / 1000 degrees in real mode and raw degrees in
//!   integer mode. Op 39 follows the label (arc sine) and gives degrees:
//!   thousandths in real mode, whole degrees (rounded, as the value comes from
//!   a floating-point function) in integer mode.
//! - Ops 41/42 in real mode add or subtract the immediate as a whole real
//!   number, and 0 means 1.000.
//! - Op 28 with k = 1 gives the sum itself, n; n must be a whole number ≥ 0.
//! - Conditions (20, 21, 29–32) that fail skip the following words up to the
//!   next op 22, which ends all open conditions; a condition met while skipping
//!   is skipped itself. An unknown condition runs the section and then joins
//!   the outcome with the state before it: parameters on which the two differ
//!   become unknown.
//! - Op 33 runs the words held in op1 … target, decoded one by one just before
//!   each runs (a program may rewrite its own later words), and ends the
//!   arithmetic of the block. A word after an op 33 that runs is an error. A
//!   program may start another (or itself) as its last word; more than
//!   [`MAX_PROGRAMS`] starts in one block are an error. An unknown word makes
//!   every parameter unknown and ends the program.
//! - Op 34 copies as if through a buffer, so overlapping ranges are fine; op 35
//!   rejects overlapping ranges. Op 45 may restore any number of times after
//!   one op 44; a second op 44 replaces the saved copy.

use std::fmt;

use ncc_syntax::TextRange;

use crate::{
    lower::{BlockData, Value},
    machine::MachineConfig,
};

/// A parameter value as the control stores it: a signed integer in thousandths.
/// `R1=864` stores 864 (0.864 as a real value), `R1=864.` stores 864000.
pub type Raw = i64;

/// The raw value of a literal as a parameter stores it: without a decimal
/// point the digits are thousandths (`R1=864` is 0.864), with one the
/// value is in units (`R1=864.` is 864.000).
pub fn literal_raw(value: &ncc_syntax::Decimal) -> Option<Raw> {
    let raw = if value.has_point() { value.scaled(3)? } else { value.scaled(0)? };
    Raw::try_from(raw).ok()
}

/// The number of program parameters, R0–R95.
pub const PARAMETER_COUNT: usize = 96;

/// The largest magnitude of a parameter, 69999.999 as a real value.
pub const MAX_RAW: Raw = 69_999_999;

/// How many programs (op 33) one block may start before the evaluator
/// assumes they call each other without end.
pub const MAX_PROGRAMS: u32 = 1000;

/// The "true" result of comparisons, parity and TEST: `GRxx` becomes G73, a jump.
const JUMP: i128 = 73;
/// The "false" result: `GRxx` becomes G78, which does nothing.
const NO_JUMP: i128 = 78;

/// A decoded control word `±CCAABBTT`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ControlWord {
    /// The sign `-`: the operation works on raw integers instead of real values.
    pub integer: bool,
    /// Decades 8–7.
    pub op: u8,
    /// Decades 6–5.
    pub op1: u8,
    /// Decades 4–3.
    pub op2: u8,
    /// Decades 2–1.
    pub target: u8,
}

impl ControlWord {
    /// Decodes the raw value of a control parameter. The digits of the raw integer are the
    /// decades (decade 1 rightmost); more than 8 digits is an error.
    pub fn decode(raw: Raw) -> Result<ControlWord, ArithError> {
        let digits = raw.unsigned_abs();
        if digits > 99_999_999 {
            return Err(ArithError::ControlWordTooLong(raw));
        }
        // Each field is two decades; `low` is the number of decades to its right.
        let field = |low: u32| (digits / 10u64.pow(low) % 100) as u8;
        Ok(ControlWord { integer: raw < 0, op: field(6), op1: field(4), op2: field(2), target: field(0) })
    }
}

/// Program parameters R0–R95. `None` = not known (the static analysis uses this; the executor
/// starts with the machine's values or zero).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Parameters {
    values: [Option<Raw>; PARAMETER_COUNT],
    /// The copy made by SAVE (op 44); `None` until the first SAVE.
    saved: Option<Box<[Option<Raw>; PARAMETER_COUNT]>>,
}

impl Parameters {
    /// All parameters unknown, nothing saved.
    pub fn unknown() -> Self {
        Parameters { values: [None; PARAMETER_COUNT], saved: None }
    }

    /// All parameters zero, nothing saved.
    pub fn zeroed() -> Self {
        Parameters { values: [Some(0); PARAMETER_COUNT], saved: None }
    }

    /// The value of R`n`.
    ///
    /// # Panics
    /// If `n` is not a parameter number (0–95).
    pub fn get(&self, n: usize) -> Option<Raw> {
        self.values[n]
    }

    /// Sets R`n`; `None` makes it unknown.
    ///
    /// # Panics
    /// If `n` is not a parameter number (0–95).
    pub fn set(&mut self, n: usize, value: Option<Raw>) {
        self.values[n] = value;
    }

    /// Merges the state of another path through the same words: whatever
    /// the two disagree on becomes unknown.
    fn join(&mut self, other: &Parameters) {
        join_values(&mut self.values, &other.values);
        self.saved = match (self.saved.take(), &other.saved) {
            (None, None) => None,
            (Some(mut mine), Some(theirs)) => {
                join_values(&mut mine, theirs);
                Some(mine)
            }
            // Saved on one path only: whether a RESTORE finds a copy is unknown.
            _ => Some(Box::new([None; PARAMETER_COUNT])),
        };
    }

    /// Everything unknown, including what SAVE may have stored.
    fn forget_all(&mut self) {
        self.values = [None; PARAMETER_COUNT];
        self.saved = Some(Box::new([None; PARAMETER_COUNT]));
    }
}

fn join_values(mine: &mut [Option<Raw>; PARAMETER_COUNT], theirs: &[Option<Raw>; PARAMETER_COUNT]) {
    for (a, b) in mine.iter_mut().zip(theirs) {
        if a != b {
            *a = None;
        }
    }
}

/// What the operations that touch the machine need (positions, tables, messages).
/// The static analysis implements it returning None / doing nothing ([`UnknownMachine`]).
///
/// Tables of ops 49 and 50 (decade 6 of the word): 1 = corrections, 2 = offsets
/// (zero shifts), 3 = machine constants, 4 = block register BWRK, 5 = block
/// register AWRK. The row is decades 4–3 of the word: the correction entry
/// 1–99, the offset 53–59 (G53–G59), or the M or G group of a block register;
/// for machine constants it is the constant's number, decades 4–3 plus 100 ×
/// decade 5, and the column is then 0. Otherwise the column is decade 5; for
/// the block registers 1 = M, 2 = G, 3 = P, 4 = H, 5 = S, 6 = T, 7 = Q, 8 = D.
pub trait Machine {
    /// The measured position of axis 1–6 (op 25), raw (thousandths of mm).
    fn measured_position(&self, axis: u8) -> Option<Raw>;
    /// The programmed coordinate of axis 1–6 (op 26), raw.
    fn programmed_position(&self, axis: u8) -> Option<Raw>;
    /// A value of a table (op 49).
    fn read_table(&self, table: u8, row: u16, column: u16) -> Option<Raw>;
    /// Writes a value into the correction (1) or offset (2) table (op 50).
    /// Not called when the value is unknown.
    fn write_table(&mut self, table: u8, row: u16, column: u16, value: Raw);
    /// Shows or cancels a technologist's message (op 51).
    fn message(&mut self, message: Message);
}

/// A machine about which nothing is known: for the static analysis.
#[derive(Debug, Clone, Copy, Default)]
pub struct UnknownMachine;

impl Machine for UnknownMachine {
    fn measured_position(&self, _axis: u8) -> Option<Raw> {
        None
    }
    fn programmed_position(&self, _axis: u8) -> Option<Raw> {
        None
    }
    fn read_table(&self, _table: u8, _row: u16, _column: u16) -> Option<Raw> {
        None
    }
    fn write_table(&mut self, _table: u8, _row: u16, _column: u16, _value: Raw) {}
    fn message(&mut self, _message: Message) {}
}

/// A technologist's message (op 51, `51MMPPTD`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Message {
    /// Which message text, 1–99 (decades 6–5). Where the texts are defined is
    /// not described in the manual.
    pub code: u8,
    /// The parameter shown where the text has a lone `$` (decades 4–3).
    pub parameter: u8,
    /// Its value when the word ran; the display does not update it.
    pub value: Option<Raw>,
    pub display: MessageDisplay,
}

/// How long a message stays on screen (decade 1, with the time in decade 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MessageDisplay {
    /// 0: remove the message.
    Cancel,
    /// 1: until cancelled.
    Permanent,
    /// 2: for the duration of one block.
    OneBlock,
    /// 3: for 1–9 seconds.
    Seconds(u8),
}

/// Settings that change how words are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ArithConfig {
    /// Fields 50–99 name double-precision pairs. Set from machine constant 283
    /// decade 4 (0 = on, 1 = off) or, when that decade is 2, from decade 1 of
    /// R95 (0 = on, 1 = off) as it is when the block starts.
    pub double_precision: bool,
}

/// Why a control word cannot be executed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ArithError {
    /// The raw value has more than 8 digits (e.g. written with a decimal point).
    ControlWordTooLong(Raw),
    /// Operation 43 or 52–99.
    UndefinedOperation(u8),
    /// Operations 36 and 40, which the manual names without describing them.
    UndocumentedOperation(u8),
    /// A field holds a value the operation does not accept.
    FieldOutOfRange {
        field: &'static str,
        value: u8,
    },
    /// A double-precision pair where the manual forbids one.
    DoublePrecisionNotAllowed {
        op: u8,
        field: &'static str,
    },
    /// A real-only operation (11, 12, 13, 27, 28) in a word with `-`.
    IntegerModeNotAllowed(u8),
    DivisionByZero,
    NegativeSquareRoot,
    LogOfNonPositive,
    /// x^y with x < 0 and a fractional y, or x = 0 and y < 0.
    PowerDomain,
    /// tan at an odd multiple of 90°.
    TangentUndefined,
    /// arcsin of a ratio outside −1 … 1.
    ArcsinDomain,
    /// The shift count of op 9 is outside ±32 (±64 with a pair).
    ShiftOutOfRange {
        count: Raw,
        limit: u8,
    },
    /// The number of terms of op 28 is not a whole number ≥ 0.
    SeriesTermCount,
    /// The result does not fit the target: ±69999.999, or 64 bits for a pair.
    Overflow,
    /// A parameter range whose first parameter comes after its last.
    InvalidRange {
        first: u8,
        last: u8,
    },
    /// The destination range of op 34, 35 or 45 runs past R95.
    RangePastEnd,
    /// Op 35 with overlapping ranges.
    OverlappingRanges,
    /// Op 45 without a preceding op 44.
    RestoreWithoutSave,
    /// Op 33 followed by another word.
    OperationAfterProgram,
    /// More than [`MAX_PROGRAMS`] programs started in one block.
    ProgramLoop,
    /// A half of a double-precision pair holds more than 32 bits.
    NotADoubleHalf {
        parameter: u8,
        value: Raw,
    },
    /// An error in a word of a program (op 33), held in R`parameter`.
    InProgram {
        parameter: u8,
        error: Box<ArithError>,
    },
}

impl fmt::Display for ArithError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ArithError::ControlWordTooLong(raw) => write!(
                f,
                "the control word has more than 8 digits (stored value {raw}); write it without a decimal point"
            ),
            ArithError::UndefinedOperation(op) => {
                write!(f, "operation {op:02} does not exist (the codes are 00–42 and 44–51)")
            }
            ArithError::UndocumentedOperation(op) => {
                let name = if *op == 36 { "inscribed arc" } else { "holes on a circle" };
                write!(f, "operation {op:02} ({name}) is not described in the manual, so it cannot be evaluated")
            }
            ArithError::FieldOutOfRange { field, value } => {
                write!(f, "the {field} field holds {value:02}, which is not allowed here")
            }
            ArithError::DoublePrecisionNotAllowed { op, field } => {
                write!(f, "operation {op:02} does not accept a double-precision {field} (field value 50–99)")
            }
            ArithError::IntegerModeNotAllowed(op) => write!(
                f,
                "operation {op:02} works only with real values: write the control word with `+` or without a sign"
            ),
            ArithError::DivisionByZero => f.write_str("division by zero"),
            ArithError::NegativeSquareRoot => f.write_str("square root of a negative value"),
            ArithError::LogOfNonPositive => f.write_str("logarithm of zero or of a negative value"),
            ArithError::PowerDomain => f.write_str(
                "the power is undefined: a negative base needs a whole exponent, and zero cannot have a negative one",
            ),
            ArithError::TangentUndefined => f.write_str("the tangent of an odd multiple of 90° is undefined"),
            ArithError::ArcsinDomain => f.write_str("arc sine of a ratio outside −1 … 1"),
            ArithError::ShiftOutOfRange { count, limit } => {
                write!(f, "the shift count {count} is outside ±{limit}")
            }
            ArithError::SeriesTermCount => f.write_str(
                "the number of terms of a geometric series must be a whole number ≥ 0 (convert a count with operation 23)",
            ),
            ArithError::Overflow => f.write_str(
                "the result is outside the range of the target (±69999.999, or 64 bits for a double-precision pair)",
            ),
            ArithError::InvalidRange { first, last } => {
                write!(f, "the range R{first:02}–R{last:02} is empty: its first parameter comes after its last")
            }
            ArithError::RangePastEnd => f.write_str("the destination range runs past R95"),
            ArithError::OverlappingRanges => f.write_str("the exchanged ranges overlap"),
            ArithError::RestoreWithoutSave => {
                f.write_str("RESTORE (operation 45) without a preceding SAVE (operation 44)")
            }
            ArithError::OperationAfterProgram => {
                f.write_str("PROGRAM (operation 33) must be the last operation, but another control word follows it")
            }
            ArithError::ProgramLoop => write!(
                f,
                "PROGRAM (operation 33) started more than {MAX_PROGRAMS} programs in one block: they call each other without end"
            ),
            ArithError::NotADoubleHalf { parameter, value } => {
                write!(f, "R{parameter:02} holds {value}, which cannot be half of a double-precision value")
            }
            ArithError::InProgram { parameter, error } => {
                write!(f, "in the control word held in R{parameter:02}: {error}")
            }
        }
    }
}

impl std::error::Error for ArithError {}

/// Executes the control words of one G26–G29 block in order (R5, R6, R7, R8), with conditions
/// (ops 20, 21, 29–32 skip the following operations up to op 22 when false), op 33 PROGRAM,
/// and every other operation. Operands that are None make the target None (no error), so that
/// a static analysis propagates "unknown". Returns the index of the word that failed with the error.
///
/// An error in a word of a program is reported at the index of the top-level op 33, as
/// [`ArithError::InProgram`] naming the parameter that holds the failing word. The words
/// before the failing one keep their effects. `words` are decoded by the caller, so a word
/// that rewrites R6–R8 does not change what this block runs.
pub fn execute(
    words: &[ControlWord],
    params: &mut Parameters,
    machine: &mut dyn Machine,
    config: ArithConfig,
) -> Result<(), (usize, ArithError)> {
    let mut eval = Evaluator { params, machine, double_precision: config.double_precision, cut_short: None };
    let mut end = eval.sequence(words.len(), |_, i| Ok(Some(words[i])))?;
    let program_index = words.len().saturating_sub(1);
    let mut started = 0;
    while let End::Program { first, last } = end {
        started += 1;
        if started > MAX_PROGRAMS {
            // A loop that only an unknown condition keeps going is not an error.
            if eval.cut_short.is_none() {
                return Err((program_index, ArithError::ProgramLoop));
            }
            eval.params.forget_all();
            break;
        }
        let word_at = |params: &Parameters, i| params.get(first + i).map(ControlWord::decode).transpose();
        let in_program = |(i, error)| {
            (program_index, ArithError::InProgram { parameter: (first + i) as u8, error: Box::new(error) })
        };
        end = eval.sequence(last - first + 1, word_at).map_err(in_program)?;
    }
    if let Some(other) = eval.cut_short.take() {
        eval.params.join(&other);
    }
    Ok(())
}

/// What a block's G26–G29 did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BlockArithmetic {
    /// The block has no G26–G29.
    None,
    /// A control word the block runs (R5–R8) is not known, so any
    /// parameter may have changed.
    UnknownWord,
    /// The words ran; with `Err`, the one that failed (the words before it
    /// kept their effects).
    Ran {
        /// The G26–G29 word, relative to the block.
        function: TextRange,
        words: Vec<ControlWord>,
        result: Result<(), ArithError>,
    },
}

/// Applies a block's `R=` assignments. A value that is not known (a
/// parameter not known, or out of range) makes the parameter unknown: it
/// no longer holds what it held before. The assignments run before the
/// block's arithmetic and after its motion, which uses the values from
/// before the block (02 §7.1).
pub fn assign(block: &BlockData, params: &mut Parameters) {
    for assignment in &block.assignments {
        let Some(index) = assignment.index.map(|i| i as usize).filter(|&i| i < PARAMETER_COUNT) else { continue };
        let value = match assignment.value.as_ref() {
            Some(Value::Literal(decimal)) => literal_raw(decimal),
            Some(value) => reference(value, params),
            None => None,
        };
        params.set(index, value.filter(|raw| raw.abs() <= MAX_RAW));
    }
}

/// The raw value a parameter reference (`R5`, `-R5`) reads, its sign
/// applied; `None` for a literal or a parameter that is not known.
pub fn reference(value: &Value, params: &Parameters) -> Option<Raw> {
    let Value::Parameter { negative, index: Some(index), .. } = *value else { return None };
    let raw = params.get(usize::try_from(index).ok().filter(|&i| i < PARAMETER_COUNT)?)?;
    Some(if negative { -raw } else { raw })
}

/// Runs a block's G26–G29: 1–4 control words from the current R5–R8, in
/// that order, after the block's assignments (02 §7.1).
pub fn compute(
    block: &BlockData,
    params: &mut Parameters,
    machine: &mut dyn Machine,
    config: &MachineConfig,
) -> BlockArithmetic {
    let Some((code, word)) = block.codes(b'G').find(|(code, _)| (26..=29).contains(code)) else {
        return BlockArithmetic::None;
    };
    let function = word.range;
    let mut words = Vec::with_capacity(4);
    for slot in 5..5 + (code - 25) as usize {
        match params.get(slot).map(ControlWord::decode) {
            Some(Ok(word)) => words.push(word),
            Some(Err(error)) => return BlockArithmetic::Ran { function, words, result: Err(error) },
            None => return BlockArithmetic::UnknownWord,
        }
    }
    let double_precision = config.double_precision(params.get(95)).unwrap_or(false);
    let result = execute(&words, params, machine, ArithConfig { double_precision }).map_err(|(_, error)| error);
    BlockArithmetic::Ran { function, words, result }
}

/// How a sequence of words ended.
enum End {
    Finished,
    /// Op 33 as the last word: run R`first` … R`last` next.
    Program {
        first: usize,
        last: usize,
    },
}

/// What a word asks of the sequence it is in.
enum Flow {
    Next,
    /// A condition with its outcome, `None` if unknown.
    Condition(Option<bool>),
    Program {
        first: usize,
        last: usize,
    },
}

/// Where a field's value lives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Slot {
    Single(usize),
    /// R`n` (low 32 bits) and R`n+1` (high 32 bits).
    Pair(usize),
}

struct Evaluator<'a> {
    params: &'a mut Parameters,
    machine: &'a mut dyn Machine,
    double_precision: bool,
    /// States of paths that an op 33 inside an unknown condition left behind:
    /// the path on which the condition failed ended there. Joined at the end.
    cut_short: Option<Parameters>,
}

impl Evaluator<'_> {
    /// Runs `len` words; `word_at` gives word `i`, `None` if it is unknown.
    fn sequence(
        &mut self,
        len: usize,
        word_at: impl Fn(&Parameters, usize) -> Result<Option<ControlWord>, ArithError>,
    ) -> Result<End, (usize, ArithError)> {
        let mut skipping = false;
        // The state at an unknown condition, had it failed (joined with any later ones).
        let mut pending: Option<Parameters> = None;
        for i in 0..len {
            let Some(word) = word_at(self.params, i).map_err(|e| (i, e))? else {
                // An unknown word may do anything, including ending the program.
                self.params.forget_all();
                return Ok(End::Finished);
            };
            if word.op == 22 {
                if let Some(other) = pending.take() {
                    self.params.join(&other);
                }
                skipping = false;
                continue;
            }
            if skipping {
                continue;
            }
            match self.step(word).map_err(|e| (i, e))? {
                Flow::Next | Flow::Condition(Some(true)) => {}
                Flow::Condition(Some(false)) => skipping = true,
                Flow::Condition(None) => {
                    pending = Some(match pending {
                        Some(mut other) => {
                            other.join(self.params);
                            other
                        }
                        None => self.params.clone(),
                    });
                }
                Flow::Program { first, last } => {
                    if i + 1 < len {
                        return Err((i, ArithError::OperationAfterProgram));
                    }
                    if let Some(other) = pending {
                        match &mut self.cut_short {
                            Some(cut) => cut.join(&other),
                            None => self.cut_short = Some(other),
                        }
                    }
                    return Ok(End::Program { first, last });
                }
            }
        }
        if let Some(other) = pending {
            self.params.join(&other);
        }
        Ok(End::Finished)
    }

    fn step(&mut self, w: ControlWord) -> Result<Flow, ArithError> {
        match w.op {
            20 | 21 | 29..=32 => {
                let a = self.slot(w.op1, "op1")?;
                let b = self.slot(w.op2, "op2")?;
                let outcome = match (self.read(a)?, self.read(b)?) {
                    (Some(a), Some(b)) => Some(compare(w.op, a, b)),
                    _ => None,
                };
                Ok(Flow::Condition(outcome))
            }
            33 => {
                let first = self.parameter(w.op1, "op1")?;
                let last = self.parameter(w.target, "target")?;
                if first > last {
                    return Err(ArithError::InvalidRange { first: w.op1, last: w.target });
                }
                Ok(Flow::Program { first, last })
            }
            _ => {
                self.operate(w)?;
                Ok(Flow::Next)
            }
        }
    }

    /// Every operation except the conditions, 22 and 33.
    fn operate(&mut self, w: ControlWord) -> Result<(), ArithError> {
        let integer = w.integer;
        match w.op {
            // The sign has no effect on these.
            0 => self.unary(w, Ok),
            1 => self.binary(w, |a, b| Ok(a + b)),
            2 => self.binary(w, |a, b| Ok(a - b)),
            7 => self.unary(w, |a| Ok(a.abs())),
            8 => self.unary(w, |a| Ok(-a)),
            15..=19 => self.binary(w, |a, b| Ok(if compare(w.op, a, b) { JUMP } else { NO_JUMP })),
            23 => self.unary(w, |a| Ok(a * 1000)),
            24 => self.unary(w, |a| Ok(a / 1000)),
            46 | 47 => self.unary(w, |a| Ok(if (a % 2 != 0) == (w.op == 46) { JUMP } else { NO_JUMP })),

            // Real and integer mode differ.
            3 => self.binary(w, |a, b| Ok(if integer { a * b } else { div_round(a * b, 1000) })),
            4 => self.binary(w, |a, b| divide(a, b, integer)),
            5 => self.unary(w, |a| Ok(if integer { a * a } else { div_round(a * a, 1000) })),
            6 => self.unary(w, |a| {
                let radicand = if integer { a } else { a * 1000 };
                let radicand = u128::try_from(radicand).map_err(|_| ArithError::NegativeSquareRoot)?;
                Ok(square_root(radicand, !integer))
            }),
            9 => {
                let (value, count, target) =
                    (self.slot(w.op1, "op1")?, self.slot(w.op2, "op2")?, self.slot(w.target, "target")?);
                let limit = if matches!(value, Slot::Pair(_)) || matches!(target, Slot::Pair(_)) { 64 } else { 32 };
                self.apply2(value, count, target, |a, n| shift(a, n, limit))
            }
            10 => self.unary(w, |a| divide(if integer { 1 } else { 1000 }, a, integer)),
            14 => self.binary(w, |a, b| {
                let sum = a.unsigned_abs().pow(2) + b.unsigned_abs().pow(2);
                Ok(square_root(sum, !integer))
            }),
            37 | 38 => self.unary(w, |a| {
                let (period, unit) = if integer { (360, 1.0) } else { (360_000, 1000.0) };
                let radians = (a.rem_euclid(period) as f64 / unit).to_radians();
                let value = if w.op == 37 { radians.sin() } else { radians.cos() };
                Ok((value * 1e7).round() as i128)
            }),
            39 => self.binary(w, |a, b| {
                if b == 0 {
                    return Err(ArithError::DivisionByZero);
                }
                if a.abs() > b.abs() {
                    return Err(ArithError::ArcsinDomain);
                }
                let degrees = (a as f64 / b as f64).asin().to_degrees();
                if integer { Ok(degrees.round() as i128) } else { real_result(degrees) }
            }),
            41 | 42 => {
                let step = i128::from(if w.op2 == 0 { 1 } else { w.op2 }) * if integer { 1 } else { 1000 };
                let step = if w.op == 41 { step } else { -step };
                let (value, target) = (self.slot(w.op1, "op1")?, self.slot(w.target, "target")?);
                self.apply1(value, target, |a| Ok(a + step))
            }

            // Real values only, or fields that are not plain operands.
            11..=13 | 27 | 28 => self.real_only(w),
            25 | 26 => self.position(w),
            34 => self.move_parameters(w),
            35 => self.exchange_parameters(w),
            44 => {
                self.params.saved = Some(Box::new(self.params.values));
                Ok(())
            }
            45 => self.restore(w),
            48 => self.logic(w),
            49 => self.read_table(w),
            50 => self.write_table(w),
            51 => self.message(w),
            36 | 40 => Err(ArithError::UndocumentedOperation(w.op)),
            _ => Err(ArithError::UndefinedOperation(w.op)),
        }
    }

    /// Ops 11, 12, 13, 27 and 28: real values only, some fields single only.
    fn real_only(&mut self, w: ControlWord) -> Result<(), ArithError> {
        if w.integer {
            return Err(ArithError::IntegerModeNotAllowed(w.op));
        }
        let real = |raw: i128| raw as f64 / 1000.0;
        match w.op {
            11 => {
                let (x, target) = (self.single(w, w.op1, "op1")?, self.slot(w.target, "target")?);
                self.apply1(x, target, |a| real_result(real(a).exp2()))
            }
            12 => {
                let (x, target) = (self.slot(w.op1, "op1")?, self.single(w, w.target, "target")?);
                self.apply1(x, target, |a| {
                    if a <= 0 {
                        return Err(ArithError::LogOfNonPositive);
                    }
                    real_result(real(a).log2())
                })
            }
            13 => {
                let (x, y) = (self.single(w, w.op1, "op1")?, self.single(w, w.op2, "op2")?);
                let target = self.slot(w.target, "target")?;
                self.apply2(x, y, target, |a, b| {
                    if (a < 0 && b % 1000 != 0) || (a == 0 && b < 0) {
                        return Err(ArithError::PowerDomain);
                    }
                    real_result(real(a).powf(real(b)))
                })
            }
            27 => {
                let (x, target) = (self.single(w, w.op1, "op1")?, self.slot(w.target, "target")?);
                self.apply1(x, target, |a| {
                    // tan repeats every 180°; reducing exactly first keeps 90° exact.
                    let a = a.rem_euclid(180_000);
                    if a == 90_000 {
                        return Err(ArithError::TangentUndefined);
                    }
                    real_result(real(a).to_radians().tan())
                })
            }
            _ => {
                let (k, n) = (self.single(w, w.op1, "op1")?, self.single(w, w.op2, "op2")?);
                let target = self.slot(w.target, "target")?;
                self.apply2(k, n, target, |k, n| {
                    if n < 0 || n % 1000 != 0 {
                        return Err(ArithError::SeriesTermCount);
                    }
                    if k == 1000 {
                        return Ok(n);
                    }
                    let k = real(k);
                    real_result((k.powf(real(n)) - 1.0) / (k - 1.0))
                })
            }
        }
    }

    /// Ops 25 and 26: positions of the axes named (not parameters) in op1 and op2.
    fn position(&mut self, w: ControlWord) -> Result<(), ArithError> {
        let position = |machine: &dyn Machine, axis| {
            let raw = if w.op == 25 { machine.measured_position(axis) } else { machine.programmed_position(axis) };
            raw.map(i128::from)
        };
        let first = axis(w.op1, "op1")?;
        match self.slot(w.target, "target")? {
            single @ Slot::Single(_) => {
                let value = position(self.machine, first);
                self.write(single, value)
            }
            Slot::Pair(n) => {
                let second = axis(w.op2, "op2")?;
                let values = (position(self.machine, first), position(self.machine, second));
                self.write(Slot::Single(n), values.0)?;
                self.write(Slot::Single(n + 1), values.1)
            }
        }
    }

    /// Op 34: R[target …] := R[op1 … op2]; op1 = 99 clears R[target … op2].
    fn move_parameters(&mut self, w: ControlWord) -> Result<(), ArithError> {
        if w.op1 == 99 {
            let last = self.parameter(w.op2, "op2")?;
            let first = self.parameter(w.target, "target")?;
            if first > last {
                return Err(ArithError::InvalidRange { first: w.target, last: w.op2 });
            }
            self.params.values[first..=last].fill(Some(0));
            return Ok(());
        }
        let (source, destination) = self.ranges(w)?;
        self.params.values.copy_within(source, destination);
        Ok(())
    }

    /// Op 35: R[op1 … op2] ⇄ R[target …].
    fn exchange_parameters(&mut self, w: ControlWord) -> Result<(), ArithError> {
        let (source, destination) = self.ranges(w)?;
        let len = source.len();
        if source.start < destination + len && destination < source.end {
            return Err(ArithError::OverlappingRanges);
        }
        for (i, j) in source.zip(destination..) {
            self.params.values.swap(i, j);
        }
        Ok(())
    }

    /// Op 45: saved R[op1 … op2] → R[target …]; all three 0 restores everything.
    fn restore(&mut self, w: ControlWord) -> Result<(), ArithError> {
        let all = w.op1 == 0 && w.op2 == 0 && w.target == 0;
        let range = if all { None } else { Some(self.ranges(w)?) };
        let saved = self.params.saved.as_deref().ok_or(ArithError::RestoreWithoutSave)?;
        match range {
            None => self.params.values = *saved,
            Some((source, destination)) => {
                let len = source.len();
                self.params.values[destination..destination + len].copy_from_slice(&saved[source]);
            }
        }
        Ok(())
    }

    /// The source range op1 … op2 and the start of the destination (target)
    /// of ops 34, 35 and 45.
    fn ranges(&self, w: ControlWord) -> Result<(std::ops::Range<usize>, usize), ArithError> {
        let first = self.parameter(w.op1, "op1")?;
        let last = self.parameter(w.op2, "op2")?;
        let destination = self.parameter(w.target, "target")?;
        if first > last {
            return Err(ArithError::InvalidRange { first: w.op1, last: w.op2 });
        }
        if destination + (last - first) >= PARAMETER_COUNT {
            return Err(ArithError::RangePastEnd);
        }
        Ok((first..last + 1, destination))
    }

    /// Op 48, `48LDAATT`: logic operation L on decade D (a decimal digit of the raw value).
    fn logic(&mut self, w: ControlWord) -> Result<(), ArithError> {
        let (operation, decade) = (w.op1 / 10, u32::from(w.op1 % 10));
        if !(1..=7).contains(&operation) {
            return Err(ArithError::FieldOutOfRange { field: "logic operation", value: operation });
        }
        if !(1..=8).contains(&decade) {
            return Err(ArithError::FieldOutOfRange { field: "decade", value: decade as u8 });
        }
        let target = Slot::Single(self.parameter(w.target, "target")?);
        let value = self.read(target)?.map(i128::from);
        let result = match operation {
            1 => value.map(|v| with_digit(v, decade, 1)),
            2 => value.map(|v| with_digit(v, decade, 0)),
            3 => value.map(|v| with_digit(v, decade, i128::from(digit(v, decade) == 0))),
            _ => {
                // OR, AND, XOR and TEST read the first operand; a digit counts as a bit, 0 or not.
                let first = self.parameter(w.op2, "operand")?;
                let bit = self.params.values[first].map(|v| digit(i128::from(v), decade) != 0);
                match operation {
                    7 => bit.map(|set| if set { JUMP } else { NO_JUMP }),
                    _ => value.zip(bit).map(|(v, a)| {
                        let b = digit(v, decade) != 0;
                        let set = match operation {
                            4 => a | b,
                            5 => a & b,
                            _ => a ^ b,
                        };
                        with_digit(v, decade, i128::from(set))
                    }),
                }
            }
        };
        self.write(target, result)
    }

    /// Op 49, `49TCSSPP`: table T, column C, row SS → R[PP].
    fn read_table(&mut self, w: ControlWord) -> Result<(), ArithError> {
        let (table, column, source) = (w.op1 / 10, w.op1 % 10, w.op2);
        let (row, column) = match table {
            1 | 2 => (table_row(table, source)?, table_column(column, 9)?),
            3 => (u16::from(source) + 100 * u16::from(column), 0),
            4 | 5 => (u16::from(source), table_column(column, 8)?),
            _ => return Err(ArithError::FieldOutOfRange { field: "table", value: table }),
        };
        let target = Slot::Single(self.parameter(w.target, "target")?);
        let value = self.machine.read_table(table, row, column);
        self.write(target, value.map(i128::from))
    }

    /// Op 50, `50TCPPRR`: R[PP] → table T (1 or 2), column C, row RR.
    fn write_table(&mut self, w: ControlWord) -> Result<(), ArithError> {
        let (table, column) = (w.op1 / 10, w.op1 % 10);
        if !(1..=2).contains(&table) {
            return Err(ArithError::FieldOutOfRange { field: "table", value: table });
        }
        let column = table_column(column, 9)?;
        let source = self.parameter(w.op2, "op2")?;
        let row = table_row(table, w.target)?;
        if let Some(value) = self.params.values[source] {
            self.machine.write_table(table, row, column, value);
        }
        Ok(())
    }

    /// Op 51, `51MMPPTD`: message MM with R[PP], time T, display mode D.
    fn message(&mut self, w: ControlWord) -> Result<(), ArithError> {
        if w.op1 == 0 {
            return Err(ArithError::FieldOutOfRange { field: "message code", value: 0 });
        }
        let parameter = self.parameter(w.op2, "op2")?;
        let (seconds, mode) = (w.target / 10, w.target % 10);
        let display = match mode {
            0 => MessageDisplay::Cancel,
            1 => MessageDisplay::Permanent,
            2 => MessageDisplay::OneBlock,
            3 if seconds > 0 => MessageDisplay::Seconds(seconds),
            3 => return Err(ArithError::FieldOutOfRange { field: "display time", value: seconds }),
            _ => return Err(ArithError::FieldOutOfRange { field: "display mode", value: mode }),
        };
        let value = self.params.values[parameter];
        self.machine.message(Message { code: w.op1, parameter: w.op2, value, display });
        Ok(())
    }

    /// target := f(op1), with the standard fields.
    fn unary(&mut self, w: ControlWord, f: impl FnOnce(i128) -> Result<i128, ArithError>) -> Result<(), ArithError> {
        let (a, target) = (self.slot(w.op1, "op1")?, self.slot(w.target, "target")?);
        self.apply1(a, target, f)
    }

    /// target := f(op1, op2), with the standard fields.
    fn binary(
        &mut self,
        w: ControlWord,
        f: impl FnOnce(i128, i128) -> Result<i128, ArithError>,
    ) -> Result<(), ArithError> {
        let (a, b) = (self.slot(w.op1, "op1")?, self.slot(w.op2, "op2")?);
        let target = self.slot(w.target, "target")?;
        self.apply2(a, b, target, f)
    }

    fn apply1(
        &mut self,
        a: Slot,
        target: Slot,
        f: impl FnOnce(i128) -> Result<i128, ArithError>,
    ) -> Result<(), ArithError> {
        let result = self.read(a)?.map(|a| f(i128::from(a))).transpose()?;
        self.write(target, result)
    }

    fn apply2(
        &mut self,
        a: Slot,
        b: Slot,
        target: Slot,
        f: impl FnOnce(i128, i128) -> Result<i128, ArithError>,
    ) -> Result<(), ArithError> {
        let result = match (self.read(a)?, self.read(b)?) {
            (Some(a), Some(b)) => Some(f(i128::from(a), i128::from(b))?),
            _ => None,
        };
        self.write(target, result)
    }

    /// An operand or target field: 50–99 name a pair when double precision is on.
    fn slot(&self, field: u8, name: &'static str) -> Result<Slot, ArithError> {
        match field {
            50.. if self.double_precision => Ok(Slot::Pair(usize::from(field - 50))),
            0..=95 => Ok(Slot::Single(usize::from(field))),
            _ => Err(ArithError::FieldOutOfRange { field: name, value: field }),
        }
    }

    /// A field where the manual forbids double precision.
    fn single(&self, w: ControlWord, field: u8, name: &'static str) -> Result<Slot, ArithError> {
        match self.slot(field, name)? {
            Slot::Pair(_) => Err(ArithError::DoublePrecisionNotAllowed { op: w.op, field: name }),
            single => Ok(single),
        }
    }

    /// A field that names a parameter directly, whatever the double precision.
    fn parameter(&self, field: u8, name: &'static str) -> Result<usize, ArithError> {
        let n = usize::from(field);
        if n < PARAMETER_COUNT { Ok(n) } else { Err(ArithError::FieldOutOfRange { field: name, value: field }) }
    }

    fn read(&self, slot: Slot) -> Result<Option<Raw>, ArithError> {
        match slot {
            Slot::Single(n) => Ok(self.params.values[n]),
            Slot::Pair(n) => {
                let half = |i: usize| {
                    self.params.values[i]
                        .map(|v| {
                            i32::try_from(v).map_err(|_| ArithError::NotADoubleHalf { parameter: i as u8, value: v })
                        })
                        .transpose()
                };
                let (low, high) = (half(n)?, half(n + 1)?);
                Ok(low.zip(high).map(|(low, high)| (i64::from(high) << 32) | i64::from(low as u32)))
            }
        }
    }

    fn write(&mut self, slot: Slot, value: Option<i128>) -> Result<(), ArithError> {
        match slot {
            Slot::Single(n) => {
                let range = -i128::from(MAX_RAW)..=i128::from(MAX_RAW);
                let value = value.map(|v| if range.contains(&v) { Ok(v as Raw) } else { Err(ArithError::Overflow) });
                self.params.values[n] = value.transpose()?;
            }
            Slot::Pair(n) => {
                let value = value.map(|v| Raw::try_from(v).map_err(|_| ArithError::Overflow)).transpose()?;
                // The casts take the low and the high 32 bits.
                self.params.values[n] = value.map(|v| Raw::from(v as i32));
                self.params.values[n + 1] = value.map(|v| v >> 32);
            }
        }
        Ok(())
    }
}

fn compare<T: Ord>(op: u8, a: T, b: T) -> bool {
    match op {
        15 | 29 => a > b,
        16 | 30 => a >= b,
        17 | 31 => a < b,
        18 | 32 => a <= b,
        21 => a != b,
        _ => a == b,
    }
}

/// n / d rounded to the nearest integer, halves away from zero.
fn div_round(n: i128, d: i128) -> i128 {
    let (q, r) = (n / d, n % d);
    if 2 * r.abs() >= d.abs() { q + (n.signum() * d.signum()) } else { q }
}

fn divide(a: i128, b: i128, integer: bool) -> Result<i128, ArithError> {
    match b {
        0 => Err(ArithError::DivisionByZero),
        _ if integer => Ok(a / b),
        _ => Ok(div_round(a * 1000, b)),
    }
}

/// √n, rounded to the nearest integer or (integer mode) truncated.
fn square_root(n: u128, round: bool) -> i128 {
    let s = n.isqrt();
    // n lies between s² and (s + 1)², and above (s + ½)² = s² + s + ¼ exactly when n − s² > s.
    let s = if round && n - s * s > s { s + 1 } else { s };
    s as i128
}

/// value · 2^count, by shifting the binary value (a right shift rounds down).
fn shift(value: i128, count: i128, limit: u8) -> Result<i128, ArithError> {
    if count.abs() > i128::from(limit) {
        let count = Raw::try_from(count).unwrap_or(if count < 0 { Raw::MIN } else { Raw::MAX });
        return Err(ArithError::ShiftOutOfRange { count, limit });
    }
    if count >= 0 { value.checked_mul(1 << count).ok_or(ArithError::Overflow) } else { Ok(value >> -count) }
}

/// A real result as raw thousandths.
fn real_result(x: f64) -> Result<i128, ArithError> {
    let raw = (x * 1000.0).round();
    // Anything near i64's range overflows every target; the bound keeps the cast exact.
    if raw.is_finite() && raw.abs() < 1e20 { Ok(raw as i128) } else { Err(ArithError::Overflow) }
}

/// An axis number of ops 25/26.
fn axis(field: u8, name: &'static str) -> Result<u8, ArithError> {
    if (1..=6).contains(&field) { Ok(field) } else { Err(ArithError::FieldOutOfRange { field: name, value: field }) }
}

/// The row of the correction (1–99) or offset (53–59) table.
fn table_row(table: u8, row: u8) -> Result<u16, ArithError> {
    let (valid, field) = if table == 1 { (1..=99, "correction entry") } else { (53..=59, "offset") };
    if valid.contains(&row) { Ok(u16::from(row)) } else { Err(ArithError::FieldOutOfRange { field, value: row }) }
}

fn table_column(column: u8, last: u8) -> Result<u16, ArithError> {
    if (1..=last).contains(&column) {
        Ok(u16::from(column))
    } else {
        Err(ArithError::FieldOutOfRange { field: "column", value: column })
    }
}

/// Decimal digit `decade` (1 = rightmost) of |value|.
fn digit(value: i128, decade: u32) -> i128 {
    value.abs() / 10i128.pow(decade - 1) % 10
}

/// `value` with decimal digit `decade` of its magnitude replaced; the sign stays.
fn with_digit(value: i128, decade: u32, new: i128) -> i128 {
    let place = 10i128.pow(decade - 1);
    let magnitude = value.abs() + (new - digit(value, decade)) * place;
    if value < 0 { -magnitude } else { magnitude }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A machine with fixed positions and table values that records what it is told.
    #[derive(Debug, Default)]
    struct TestMachine {
        measured: Vec<(u8, Raw)>,
        programmed: Vec<(u8, Raw)>,
        table: Vec<((u8, u16, u16), Raw)>,
        written: Vec<(u8, u16, u16, Raw)>,
        messages: Vec<Message>,
    }

    fn lookup<K: PartialEq>(entries: &[(K, Raw)], key: K) -> Option<Raw> {
        entries.iter().find(|(k, _)| *k == key).map(|&(_, v)| v)
    }

    impl Machine for TestMachine {
        fn measured_position(&self, axis: u8) -> Option<Raw> {
            lookup(&self.measured, axis)
        }
        fn programmed_position(&self, axis: u8) -> Option<Raw> {
            lookup(&self.programmed, axis)
        }
        fn read_table(&self, table: u8, row: u16, column: u16) -> Option<Raw> {
            lookup(&self.table, (table, row, column))
        }
        fn write_table(&mut self, table: u8, row: u16, column: u16, value: Raw) {
            self.written.push((table, row, column, value));
        }
        fn message(&mut self, message: Message) {
            self.messages.push(message);
        }
    }

    /// A value as a declaration stores it: `R1=864` → 864, `R1=864.` → 864000.
    fn r(text: &str) -> Raw {
        match text.split_once('.') {
            None => text.parse().unwrap(),
            Some((int, frac)) => {
                let magnitude = int.trim_start_matches(['-', '+']).parse::<Raw>().unwrap_or(0) * 1000
                    + format!("{frac:0<3}").parse::<Raw>().unwrap();
                if int.starts_with('-') { -magnitude } else { magnitude }
            }
        }
    }

    fn word(text: &str) -> ControlWord {
        ControlWord::decode(text.parse().unwrap()).unwrap()
    }

    /// Zeroed parameters with some declared.
    fn params(values: &[(usize, &str)]) -> Parameters {
        let mut p = Parameters::zeroed();
        for &(n, value) in values {
            p.set(n, Some(r(value)));
        }
        p
    }

    fn run_with(
        p: &mut Parameters,
        texts: &[&str],
        machine: &mut dyn Machine,
        config: ArithConfig,
    ) -> Result<(), (usize, ArithError)> {
        let words: Vec<_> = texts.iter().map(|t| word(t)).collect();
        execute(&words, p, machine, config)
    }

    fn run(p: &mut Parameters, texts: &[&str]) -> Result<(), (usize, ArithError)> {
        run_with(p, texts, &mut UnknownMachine, ArithConfig::default())
    }

    const DOUBLE: ArithConfig = ArithConfig { double_precision: true };

    /// Runs one word and returns its target.
    fn result(values: &[(usize, &str)], text: &str) -> Option<Raw> {
        let mut p = params(values);
        run(&mut p, &[text]).unwrap();
        p.get(usize::from(word(text).target))
    }

    fn error(values: &[(usize, &str)], text: &str) -> ArithError {
        error_with(values, text, ArithConfig::default())
    }

    fn error_with(values: &[(usize, &str)], text: &str, config: ArithConfig) -> ArithError {
        let mut p = params(values);
        run_with(&mut p, &[text], &mut UnknownMachine, config).unwrap_err().1
    }

    fn field(field: &'static str, value: u8) -> ArithError {
        ArithError::FieldOutOfRange { field, value }
    }

    #[test]
    fn decodes_sign_and_fields() {
        assert_eq!(word("-42120212"), ControlWord { integer: true, op: 42, op1: 12, op2: 2, target: 12 });
        assert_eq!(word("19141706"), ControlWord { integer: false, op: 19, op1: 14, op2: 17, target: 6 });
        assert_eq!(word("+00280039"), ControlWord { integer: false, op: 0, op1: 28, op2: 0, target: 39 });
        assert_eq!(ControlWord::decode(99_999_999).unwrap().op, 99);
        // `R5=15313024.` stores 15313024000.
        assert_eq!(ControlWord::decode(15_313_024_000), Err(ArithError::ControlWordTooLong(15_313_024_000)));
        assert!(ControlWord::decode(Raw::MIN).is_err());
    }

    #[test]
    fn copy_add_subtract_absolute_negate_ignore_the_sign() {
        for sign in ["", "+", "-"] {
            let w = |body: &str| format!("{sign}{body}");
            assert_eq!(result(&[(13, "3")], &w("00130019")), Some(3));
            assert_eq!(result(&[(29, "10."), (24, "1.000")], &w("01292425")), Some(11_000));
            assert_eq!(result(&[(29, "10."), (28, "12.")], &w("02292829")), Some(-2_000));
            assert_eq!(result(&[(46, "5.5")], &w("02464646")), Some(0));
            assert_eq!(result(&[(28, "-12.")], &w("07280028")), Some(12_000));
            assert_eq!(result(&[(10, "100.0")], &w("08100010")), Some(-100_000));
        }
    }

    #[test]
    fn multiply_real_and_integer() {
        // The manual's R12 = 0.004 (declared `4`) times R10 = 100.000.
        assert_eq!(result(&[(12, "4"), (10, "100.0")], "03121015"), Some(400));
        assert_eq!(result(&[(12, "4"), (10, "100.0")], "-03121015"), Some(400_000));
        // 1.005 · 0.5 = 0.5025: halves round away from zero.
        assert_eq!(result(&[(1, "1.005"), (2, "0.5")], "03010203"), Some(503));
        assert_eq!(result(&[(1, "-1.005"), (2, "0.5")], "03010203"), Some(-503));
    }

    #[test]
    fn divide_real_and_integer() {
        assert_eq!(result(&[(1, "10."), (2, "4.")], "04010203"), Some(2_500));
        assert_eq!(result(&[(1, "2."), (2, "3.")], "04010203"), Some(667));
        assert_eq!(result(&[(1, "10"), (2, "4")], "-04010203"), Some(2));
        assert_eq!(result(&[(1, "-7"), (2, "2")], "-04010203"), Some(-3));
        assert_eq!(error(&[(1, "1.")], "04010203"), ArithError::DivisionByZero);
        assert_eq!(error(&[(1, "1")], "-04010203"), ArithError::DivisionByZero);
    }

    #[test]
    fn square_and_square_root() {
        assert_eq!(result(&[(10, "3.")], "05100011"), Some(9_000));
        // 0.004² = 0.000016, below a thousandth.
        assert_eq!(result(&[(10, "4")], "05100011"), Some(0));
        assert_eq!(result(&[(10, "4")], "-05100011"), Some(16));
        assert_eq!(result(&[(10, "2.")], "06100011"), Some(1_414));
        assert_eq!(result(&[(10, "2.25")], "06100011"), Some(1_500));
        assert_eq!(result(&[(10, "4")], "-06100011"), Some(2));
        assert_eq!(result(&[(10, "8")], "-06100011"), Some(2));
        assert_eq!(error(&[(10, "-1.")], "06100011"), ArithError::NegativeSquareRoot);
        assert_eq!(error(&[(10, "-4")], "-06100011"), ArithError::NegativeSquareRoot);
    }

    #[test]
    fn binary_shift() {
        // Lathe G84: R32 = -1 (declared without a point) halves the chip in diameter programming.
        for sign in ["", "-"] {
            assert_eq!(result(&[(46, "0.446"), (32, "-1")], &format!("{sign}09463242")), Some(223));
        }
        assert_eq!(result(&[(46, "0.446"), (32, "0")], "09463242"), Some(446));
        assert_eq!(result(&[(46, "0.446"), (32, "3")], "09463242"), Some(3_568));
        assert_eq!(result(&[(46, "-0.445"), (32, "-1")], "09463242"), Some(-223));
        assert_eq!(result(&[(46, "5."), (32, "-32")], "09463242"), Some(0));
        assert_eq!(error(&[(32, "33")], "09463242"), ArithError::ShiftOutOfRange { count: 33, limit: 32 });
        assert_eq!(error(&[(46, "1."), (32, "20")], "09463242"), ArithError::Overflow);
        // A pair may shift by up to 64 places.
        let mut p = params(&[(40, "1"), (32, "40")]);
        run_with(&mut p, &["09903292"], &mut UnknownMachine, DOUBLE).unwrap();
        assert_eq!((p.get(42), p.get(43)), (Some(0), Some(256)));
        assert_eq!(error_with(&[(32, "65")], "09903292", DOUBLE), ArithError::ShiftOutOfRange { count: 65, limit: 64 });
    }

    #[test]
    fn reciprocal() {
        assert_eq!(result(&[(10, "4.")], "10100011"), Some(250));
        assert_eq!(result(&[(10, "-3.")], "10100011"), Some(-333));
        assert_eq!(result(&[(10, "1")], "-10100011"), Some(1));
        assert_eq!(result(&[(10, "4")], "-10100011"), Some(0));
        assert_eq!(error(&[], "10100011"), ArithError::DivisionByZero);
    }

    #[test]
    fn power_of_two_logarithm_and_power_are_real_only() {
        assert_eq!(result(&[(10, "10.")], "11100011"), Some(1_024_000));
        assert_eq!(result(&[(10, "0.5")], "11100011"), Some(1_414));
        assert_eq!(result(&[(10, "-1.")], "11100011"), Some(500));
        assert_eq!(error(&[(10, "100.")], "11100011"), ArithError::Overflow);
        assert_eq!(result(&[(10, "8.")], "12100011"), Some(3_000));
        assert_eq!(result(&[(10, "0.5")], "12100011"), Some(-1_000));
        assert_eq!(error(&[], "12100011"), ArithError::LogOfNonPositive);
        assert_eq!(error(&[(10, "-2.")], "12100011"), ArithError::LogOfNonPositive);
        assert_eq!(result(&[(10, "2."), (11, "3.")], "13101112"), Some(8_000));
        assert_eq!(result(&[(10, "-2."), (11, "3.")], "13101112"), Some(-8_000));
        assert_eq!(result(&[(10, "4."), (11, "0.5")], "13101112"), Some(2_000));
        assert_eq!(error(&[(10, "-2."), (11, "0.5")], "13101112"), ArithError::PowerDomain);
        assert_eq!(error(&[(11, "-1.")], "13101112"), ArithError::PowerDomain);
        for op in ["11100011", "12100011", "13101112", "27100011", "28283940"] {
            let code = word(op).op;
            assert_eq!(error(&[], &format!("-{op}")), ArithError::IntegerModeNotAllowed(code));
        }
    }

    #[test]
    fn double_precision_is_refused_where_the_manual_forbids_it() {
        let refused = |text: &str, field| {
            let op = word(text).op;
            assert_eq!(error_with(&[], text, DOUBLE), ArithError::DoublePrecisionNotAllowed { op, field });
        };
        refused("11600011", "op1");
        refused("12100061", "target");
        refused("13601112", "op1");
        refused("13106112", "op2");
        refused("27600011", "op1");
        refused("28783940", "op1");
        refused("28288940", "op2");
        // Without double precision the same fields are plain parameters.
        assert_eq!(result(&[(60, "3.")], "11600011"), Some(8_000));
    }

    #[test]
    fn root_of_the_sum_of_squares() {
        assert_eq!(result(&[(10, "3."), (11, "4.")], "14101112"), Some(5_000));
        assert_eq!(result(&[(10, "1."), (11, "1.")], "14101112"), Some(1_414));
        assert_eq!(result(&[(10, "3"), (11, "4")], "-14101112"), Some(5));
        assert_eq!(result(&[(10, "1"), (11, "1")], "-14101112"), Some(1));
    }

    #[test]
    fn comparisons_store_raw_73_or_78() {
        // (op, a < b, a = b, a > b)
        let cases = [(15, 78, 78, 73), (16, 78, 73, 73), (17, 73, 78, 78), (18, 73, 73, 78), (19, 78, 73, 78)];
        for (op, less, equal, greater) in cases {
            for sign in ["", "-"] {
                let text = format!("{sign}{op}010203");
                assert_eq!(result(&[(1, "1."), (2, "2.")], &text), Some(less), "{text}");
                assert_eq!(result(&[(1, "2."), (2, "2.")], &text), Some(equal), "{text}");
                assert_eq!(result(&[(1, "3."), (2, "2.")], &text), Some(greater), "{text}");
            }
        }
    }

    #[test]
    fn conditions_skip_up_to_op_22() {
        // (op, holds for a < b, a = b, a > b)
        let cases = [
            (20, false, true, false),
            (21, true, false, true),
            (29, false, false, true),
            (30, false, true, true),
            (31, true, false, false),
            (32, true, true, false),
        ];
        for (op, less, equal, greater) in cases {
            for (a, holds) in [("1.", less), ("2.", equal), ("3.", greater)] {
                let mut p = params(&[(1, a), (2, "2."), (8, "5."), (9, "6.")]);
                let condition = format!("{op}010200");
                run(&mut p, &[&condition, "00080010", "22000000", "00090011"]).unwrap();
                assert_eq!(p.get(10), Some(if holds { 5_000 } else { 0 }), "{condition} with R1 = {a}");
                assert_eq!(p.get(11), Some(6_000), "op 22 ends the condition");
            }
        }
    }

    #[test]
    fn a_failed_condition_without_op_22_skips_the_rest_and_op_22_ends_all() {
        let mut p = params(&[(1, "1")]);
        run(&mut p, &["20010000", "00010010", "00010011"]).unwrap();
        assert_eq!((p.get(10), p.get(11)), (Some(0), Some(0)));
        // A condition met while skipping is skipped; one 22 ends both.
        let mut p = params(&[(1, "1")]);
        run(&mut p, &["20010000", "20000000", "00010010", "22000000", "00010011"]).unwrap();
        assert_eq!((p.get(10), p.get(11)), (Some(0), Some(1)));
        // Two conditions in a row must both hold.
        let mut p = params(&[(1, "1")]);
        run(&mut p, &["21010000", "20000000", "00010010", "22000000"]).unwrap();
        assert_eq!(p.get(10), Some(1));
        // Op 22 without a condition does nothing.
        assert!(run(&mut params(&[]), &["22000000"]).is_ok());
    }

    #[test]
    fn integer_real_conversion() {
        assert_eq!(result(&[(29, "5")], "+23290039"), Some(5_000));
        assert_eq!(result(&[(29, "5")], "-23290039"), Some(5_000));
        assert_eq!(error(&[(29, "70000")], "23290039"), ArithError::Overflow);
        assert_eq!(result(&[(10, "5.999")], "24100011"), Some(5));
        assert_eq!(result(&[(10, "-2.5")], "24100011"), Some(-2));
    }

    #[test]
    fn axis_positions() {
        let mut machine = TestMachine {
            measured: vec![(1, r("12.5"))],
            programmed: vec![(1, r("64.")), (2, r("4."))],
            ..TestMachine::default()
        };
        let mut p = params(&[]);
        run_with(&mut p, &["25010030", "26020031"], &mut machine, ArithConfig::default()).unwrap();
        assert_eq!((p.get(30), p.get(31)), (Some(12_500), Some(4_000)));
        // A pair target takes axis op1 into its first and axis op2 into its second parameter.
        run_with(&mut p, &["+26010283"], &mut machine, DOUBLE).unwrap();
        assert_eq!((p.get(33), p.get(34)), (Some(64_000), Some(4_000)));
        // An axis without a known position gives an unknown value.
        run_with(&mut p, &["25030030"], &mut machine, ArithConfig::default()).unwrap();
        assert_eq!(p.get(30), None);
        assert_eq!(error(&[], "25070030"), field("op1", 7));
        assert_eq!(error(&[], "26000030"), field("op1", 0));
        assert_eq!(error_with(&[], "26010083", DOUBLE), field("op2", 0));
    }

    #[test]
    fn tangent_in_degrees() {
        assert_eq!(result(&[(10, "45.")], "27100011"), Some(1_000));
        assert_eq!(result(&[(10, "135.")], "27100011"), Some(-1_000));
        assert_eq!(result(&[(10, "-45.")], "27100011"), Some(-1_000));
        assert_eq!(result(&[(10, "89.999")], "27100011"), Some(57_295_780));
        assert_eq!(error(&[(10, "90.")], "27100011"), ArithError::TangentUndefined);
        assert_eq!(error(&[(10, "-270.")], "27100011"), ArithError::TangentUndefined);
    }

    #[test]
    fn geometric_series() {
        // Lathe G84: quotient 0.8, five chips: 1 + 0.8 + 0.64 + 0.512 + 0.4096 = 3.3616.
        assert_eq!(result(&[(28, "0.8"), (39, "5.")], "+28283940"), Some(3_362));
        assert_eq!(result(&[(28, "1."), (39, "4.")], "+28283940"), Some(4_000));
        assert_eq!(result(&[(28, "2."), (39, "0")], "+28283940"), Some(0));
        // A count declared without a point must be converted with op 23 first.
        assert_eq!(error(&[(28, "0.8"), (39, "5")], "+28283940"), ArithError::SeriesTermCount);
        assert_eq!(error(&[(28, "0.8"), (39, "-1.")], "+28283940"), ArithError::SeriesTermCount);
    }

    #[test]
    fn sine_and_cosine_times_ten_million() {
        assert_eq!(result(&[(10, "30.")], "37100011"), Some(5_000_000));
        assert_eq!(result(&[(10, "90.")], "37100011"), Some(10_000_000));
        assert_eq!(result(&[(10, "-390.")], "37100011"), Some(-5_000_000));
        assert_eq!(result(&[(10, "60.")], "38100011"), Some(5_000_000));
        assert_eq!(result(&[(10, "180.")], "38100011"), Some(-10_000_000));
        // Integer mode reads the angle as whole degrees.
        assert_eq!(result(&[(10, "30")], "-37100011"), Some(5_000_000));
        assert_eq!(result(&[(10, "30")], "37100011"), Some(5_236));
    }

    #[test]
    fn arc_sine_of_a_ratio() {
        assert_eq!(result(&[(10, "1."), (11, "2.")], "39101112"), Some(30_000));
        assert_eq!(result(&[(10, "-1."), (11, "1.")], "39101112"), Some(-90_000));
        assert_eq!(result(&[(10, "1"), (11, "2")], "-39101112"), Some(30));
        assert_eq!(error(&[(10, "3."), (11, "2.")], "39101112"), ArithError::ArcsinDomain);
        assert_eq!(error(&[(10, "1.")], "39101112"), ArithError::DivisionByZero);
    }

    #[test]
    fn increment_and_decrement_take_an_immediate() {
        assert_eq!(result(&[(20, "2")], "-41200020"), Some(3));
        assert_eq!(result(&[(20, "2")], "-41200320"), Some(5));
        assert_eq!(result(&[(20, "2")], "41200020"), Some(1_002));
        assert_eq!(result(&[(12, "4")], "41120212"), Some(2_004));
        assert_eq!(result(&[(12, "4")], "-42120212"), Some(2));
        assert_eq!(result(&[(13, "3")], "-42130013"), Some(2));
        // The manual's warning: with `+` the count 0.004 loses 2.000.
        assert_eq!(result(&[(12, "4")], "42120212"), Some(-1_996));
    }

    #[test]
    fn undefined_and_undocumented_operations() {
        for op in std::iter::once(43).chain(52..=99) {
            assert_eq!(error(&[], &format!("{op}000000")), ArithError::UndefinedOperation(op));
        }
        for op in [36, 40] {
            assert_eq!(error(&[], &format!("{op}000000")), ArithError::UndocumentedOperation(op));
        }
    }

    #[test]
    fn move_parameters() {
        let mut p = params(&[(10, "1"), (11, "2"), (12, "3")]);
        run(&mut p, &["34101230"]).unwrap();
        assert_eq!([p.get(30), p.get(31), p.get(32), p.get(10)], [Some(1), Some(2), Some(3), Some(1)]);
        // Overlapping ranges move as if through a buffer.
        run(&mut p, &["34101211"]).unwrap();
        assert_eq!([p.get(11), p.get(12), p.get(13)], [Some(1), Some(2), Some(3)]);
        // op1 = 99 clears target … op2.
        let mut p = params(&[(29, "1"), (30, "1"), (40, "1"), (41, "1")]);
        run(&mut p, &["34994030"]).unwrap();
        assert_eq!([p.get(29), p.get(30), p.get(40), p.get(41)], [Some(1), Some(0), Some(0), Some(1)]);
        assert_eq!(error(&[], "34121030"), ArithError::InvalidRange { first: 12, last: 10 });
        assert_eq!(error(&[], "34993040"), ArithError::InvalidRange { first: 40, last: 30 });
        assert_eq!(error(&[], "34101294"), ArithError::RangePastEnd);
        assert_eq!(error(&[], "34109630"), field("op2", 96));
        // The fields name parameters directly, even with double precision on.
        let mut p = params(&[(60, "7")]);
        run_with(&mut p, &["34606070"], &mut UnknownMachine, DOUBLE).unwrap();
        assert_eq!(p.get(70), Some(7));
    }

    #[test]
    fn exchange_parameters() {
        let mut p = params(&[(10, "1"), (11, "2"), (30, "3"), (31, "4")]);
        run(&mut p, &["35101130"]).unwrap();
        assert_eq!([p.get(10), p.get(11), p.get(30), p.get(31)], [Some(3), Some(4), Some(1), Some(2)]);
        assert_eq!(error(&[], "35101211"), ArithError::OverlappingRanges);
        assert_eq!(error(&[], "35101210"), ArithError::OverlappingRanges);
        assert_eq!(error(&[], "35101294"), ArithError::RangePastEnd);
    }

    #[test]
    fn save_and_restore() {
        let mut p = params(&[(10, "1"), (11, "2"), (12, "3")]);
        run(&mut p, &["44000000", "34991210", "00000095"]).unwrap();
        assert_eq!([p.get(10), p.get(11), p.get(12)], [Some(0); 3]);
        // A range: saved R10 … R11 into R20 … R21.
        run(&mut p, &["45101120"]).unwrap();
        assert_eq!([p.get(20), p.get(21), p.get(10)], [Some(1), Some(2), Some(0)]);
        // Everything, and again: RESTORE keeps the copy.
        run(&mut p, &["45000000"]).unwrap();
        assert_eq!([p.get(10), p.get(11), p.get(12), p.get(20)], [Some(1), Some(2), Some(3), Some(0)]);
        p.set(10, Some(9));
        run(&mut p, &["45000000"]).unwrap();
        assert_eq!(p.get(10), Some(1));
        assert_eq!(error(&[], "45000000"), ArithError::RestoreWithoutSave);
        assert_eq!(error(&[], "45101120"), ArithError::RestoreWithoutSave);
        let mut p = params(&[]);
        assert_eq!(run(&mut p, &["44000000", "45109590"]), Err((1, ArithError::RangePastEnd)));
    }

    #[test]
    fn parity() {
        assert_eq!(result(&[(19, "3")], "46190017"), Some(73));
        assert_eq!(result(&[(19, "3")], "47190017"), Some(78));
        assert_eq!(result(&[(19, "4")], "46190017"), Some(78));
        assert_eq!(result(&[(19, "4")], "47190017"), Some(73));
        assert_eq!(result(&[(19, "-3")], "46190017"), Some(73));
    }

    #[test]
    fn logic_on_decades() {
        // The manual's switch of double precision: SET and CLR decade 1 of R95.
        assert_eq!(result(&[(95, "0")], "48110095"), Some(1));
        assert_eq!(result(&[(95, "11")], "48210095"), Some(10));
        let mut p = params(&[]);
        run_with(&mut p, &["48110095"], &mut UnknownMachine, DOUBLE).unwrap();
        assert_eq!(p.get(95), Some(1));
        assert_eq!(result(&[(20, "12345")], "48130020"), Some(12_145));
        assert_eq!(result(&[(20, "-5")], "48120020"), Some(-15));
        // NOT treats a digit as a bit.
        assert_eq!(result(&[(20, "105")], "48320020"), Some(115));
        assert_eq!(result(&[(20, "175")], "48320020"), Some(105));
        // OR, AND, XOR: decade 2 of R30 with decade 2 of R20, into R20.
        assert_eq!(result(&[(30, "10"), (20, "100")], "48423020"), Some(110));
        assert_eq!(result(&[(30, "10"), (20, "110")], "48523020"), Some(110));
        assert_eq!(result(&[(30, "0"), (20, "110")], "48523020"), Some(100));
        assert_eq!(result(&[(30, "10"), (20, "110")], "48623020"), Some(100));
        assert_eq!(result(&[(30, "10"), (20, "100")], "48623020"), Some(110));
        // TEST: 73 when decade 2 of R30 is set.
        assert_eq!(result(&[(30, "10")], "48723020"), Some(73));
        assert_eq!(result(&[(30, "105")], "48723020"), Some(78));
        assert_eq!(error(&[], "48810095"), field("logic operation", 8));
        assert_eq!(error(&[], "48190095"), field("decade", 9));
        assert_eq!(error(&[], "48100095"), field("decade", 0));
        assert_eq!(error(&[], "48110096"), field("target", 96));
        assert_eq!(error(&[], "48419620"), field("operand", 96));
    }

    #[test]
    fn read_from_tables() {
        let mut machine = TestMachine {
            table: vec![((5, 2, 1), 3), ((3, 339, 0), 1234), ((1, 12, 2), r("5.5")), ((2, 54, 1), r("-20."))],
            ..TestMachine::default()
        };
        let mut p = params(&[]);
        run_with(&mut p, &["49510224", "49333925", "49121226", "49215427"], &mut machine, ArithConfig::default())
            .unwrap();
        assert_eq!([p.get(24), p.get(25), p.get(26), p.get(27)], [Some(3), Some(1234), Some(5_500), Some(-20_000)]);
        // Nothing known there.
        run_with(&mut p, &["49110124"], &mut machine, ArithConfig::default()).unwrap();
        assert_eq!(p.get(24), None);
        assert_eq!(error(&[], "49610224"), field("table", 6));
        assert_eq!(error(&[], "49110024"), field("correction entry", 0));
        assert_eq!(error(&[], "49215224"), field("offset", 52));
        assert_eq!(error(&[], "49590224"), field("column", 9));
        assert_eq!(error(&[], "49200224"), field("offset", 2));
        assert_eq!(error(&[], "49510296"), field("target", 96));
    }

    #[test]
    fn write_to_tables() {
        let mut machine = TestMachine::default();
        let mut p = params(&[(30, "2.5")]);
        run_with(&mut p, &["50113012", "50223055"], &mut machine, ArithConfig::default()).unwrap();
        assert_eq!(machine.written, [(1, 12, 1, 2_500), (2, 55, 2, 2_500)]);
        // An unknown value is not written.
        p.set(30, None);
        run_with(&mut p, &["50113012"], &mut machine, ArithConfig::default()).unwrap();
        assert_eq!(machine.written.len(), 2);
        assert_eq!(error(&[], "50313012"), field("table", 3));
        assert_eq!(error(&[], "50103012"), field("column", 0));
        assert_eq!(error(&[], "50113000"), field("correction entry", 0));
        assert_eq!(error(&[], "50213060"), field("offset", 60));
    }

    #[test]
    fn messages() {
        let mut machine = TestMachine::default();
        let mut p = params(&[(30, "12.5")]);
        let texts = ["51073053", "51073050", "51073051", "51073052"];
        run_with(&mut p, &texts, &mut machine, ArithConfig::default()).unwrap();
        let displays: Vec<_> = machine.messages.iter().map(|m| m.display).collect();
        assert_eq!(
            displays,
            [MessageDisplay::Seconds(5), MessageDisplay::Cancel, MessageDisplay::Permanent, MessageDisplay::OneBlock]
        );
        assert_eq!(
            machine.messages[0],
            Message { code: 7, parameter: 30, value: Some(12_500), display: MessageDisplay::Seconds(5) }
        );
        assert_eq!(error(&[], "51003051"), field("message code", 0));
        assert_eq!(error(&[], "51073054"), field("display mode", 4));
        assert_eq!(error(&[], "51073003"), field("display time", 0));
        assert_eq!(error(&[], "51079651"), field("op2", 96));
    }

    #[test]
    fn program_runs_the_words_held_in_parameters() {
        // Milling G84: read the spindle direction (M group 2 of AWRK) and choose the reverse one.
        for (spindle, reverse) in [(3, 4), (4, 3)] {
            let mut machine = TestMachine { table: vec![((5, 2, 1), spindle)], ..TestMachine::default() };
            let mut p = params(&[
                (8, "4"),
                (9, "3"),
                (10, "49510220"),
                (11, "20200900"),
                (12, "00080007"),
                (13, "22000000"),
                (14, "20200800"),
                (15, "00090007"),
                (16, "22000000"),
            ]);
            run_with(&mut p, &["33100016"], &mut machine, ArithConfig::default()).unwrap();
            assert_eq!((p.get(20), p.get(7)), (Some(spindle), Some(reverse)));
        }
    }

    #[test]
    fn program_words_are_decoded_as_they_run() {
        // R10 writes the word that R11 then runs: R11 := R20 (= "00010012", R12 := R1).
        let mut p = params(&[(1, "5"), (10, "00200011"), (11, "22000000"), (20, "00010012")]);
        run(&mut p, &["33100011"]).unwrap();
        assert_eq!(p.get(12), Some(5));
    }

    #[test]
    fn program_errors() {
        // The failing word is reported at the op 33, naming its parameter.
        let mut p = params(&[(10, "00010002"), (11, "04010203")]);
        let in_r11 = |error| ArithError::InProgram { parameter: 11, error: Box::new(error) };
        assert_eq!(run(&mut p, &["00000000", "33100011"]), Err((1, in_r11(ArithError::DivisionByZero))));
        let mut p = params(&[(10, "12345678."), (11, "01000000")]);
        assert_eq!(
            run(&mut p, &["33100011"]),
            Err((
                0,
                ArithError::InProgram {
                    parameter: 10,
                    error: Box::new(ArithError::ControlWordTooLong(r("12345678.")))
                }
            ))
        );
        // Nothing may follow op 33, in a block or in a program.
        assert_eq!(run(&mut params(&[]), &["33100011", "00000000"]), Err((0, ArithError::OperationAfterProgram)));
        let mut p = params(&[(10, "33200020"), (11, "00000000")]);
        assert_eq!(
            run(&mut p, &["33100011"]),
            Err((0, ArithError::InProgram { parameter: 10, error: Box::new(ArithError::OperationAfterProgram) }))
        );
        assert_eq!(error(&[], "33110010"), ArithError::InvalidRange { first: 11, last: 10 });
        assert_eq!(error(&[], "33100096"), field("target", 96));
        // A program that starts itself without end.
        let mut p = params(&[(10, "41200020"), (11, "33100011")]);
        assert_eq!(run(&mut p, &["33100011"]), Err((0, ArithError::ProgramLoop)));
        assert_eq!(p.get(20), Some(r("1000.")), "each of the programs ran once");
    }

    #[test]
    fn a_program_may_start_another_as_its_last_word() {
        // A counting loop: R20 += 1 while R20 < R21.
        let mut p = params(&[(10, "-41200020"), (11, "31202100"), (12, "33100012"), (21, "5")]);
        run(&mut p, &["33100012"]).unwrap();
        assert_eq!(p.get(20), Some(5));
    }

    #[test]
    fn unknown_operands_give_unknown_targets() {
        let mut p = params(&[]);
        p.set(1, None);
        run(&mut p, &["01010203", "15010204", "-42010005", "00020006"]).unwrap();
        assert_eq!([p.get(3), p.get(4), p.get(5), p.get(6)], [None, None, None, Some(0)]);
        // Field errors are found even when the values are unknown.
        let mut p = Parameters::unknown();
        assert_eq!(run(&mut p, &["04979899"]), Err((0, field("op1", 97))));
        assert_eq!(run(&mut p, &["04010200"]), Ok(()));
    }

    #[test]
    fn an_unknown_condition_joins_both_outcomes() {
        let mut p = params(&[(3, "7"), (5, "8")]);
        p.set(1, None);
        // IF R1 = R2: R10 := R3, R12 := R3 ENDIF; R13 := R5.
        p.set(12, Some(7));
        run(&mut p, &["20010200", "00030010", "00030012", "22000000", "00050013"]).unwrap();
        assert_eq!(p.get(10), None, "0 if the condition fails, 7 if it holds");
        assert_eq!(p.get(12), Some(7), "7 either way");
        assert_eq!(p.get(13), Some(8), "after op 22 the outcome is known again");
        // Without op 22 the join happens at the end of the block.
        let mut p = params(&[(3, "7")]);
        p.set(1, None);
        run(&mut p, &["31010200", "00030010"]).unwrap();
        assert_eq!(p.get(10), None);
        // A known failing condition inside an unknown one.
        let mut p = params(&[(3, "7")]);
        p.set(1, None);
        run(&mut p, &["20010200", "00030010", "21000000", "00030011", "22000000"]).unwrap();
        assert_eq!((p.get(10), p.get(11)), (None, Some(0)));
    }

    #[test]
    fn unknown_program_words() {
        // A program word that is not known may do anything.
        let mut p = params(&[(1, "5"), (10, "00010002")]);
        p.set(11, None);
        run(&mut p, &["33100011"]).unwrap();
        assert_eq!((p.get(1), p.get(2)), (None, None));
        // A loop kept going by an unknown condition ends with everything unknown, not an error.
        let mut p = params(&[(10, "-41200020"), (11, "31202100"), (12, "33100012")]);
        p.set(21, None);
        run(&mut p, &["33100012"]).unwrap();
        assert_eq!(p.get(20), None);
        // PROGRAM inside an unknown condition: the path where it fails ends there.
        let mut p = params(&[(10, "00030004"), (3, "9")]);
        p.set(1, None);
        run(&mut p, &["20010200", "33100010"]).unwrap();
        assert_eq!((p.get(4), p.get(3)), (None, Some(9)));
    }

    #[test]
    fn double_precision_pairs() {
        // Fields 96–99 exist only as pairs.
        assert_eq!(error(&[], "00970010"), field("op1", 97));
        assert_eq!(error(&[], "00100099"), field("target", 99));
        // Lathe cycles: `R08=+00800085` copies R30, R31 into R35, R36, whatever they hold.
        let mut p = params(&[(30, "-70."), (31, "-100.")]);
        run_with(&mut p, &["+00800085"], &mut UnknownMachine, DOUBLE).unwrap();
        assert_eq!((p.get(35), p.get(36)), (Some(-70_000), Some(-100_000)));
        // A 64-bit value: low 32 bits first, high 32 bits second.
        let mut p = params(&[(1, "60000."), (2, "60000.")]);
        run_with(&mut p, &["-03010250"], &mut UnknownMachine, DOUBLE).unwrap();
        let product: Raw = 60_000_000 * 60_000_000;
        assert_eq!((p.get(0), p.get(1)), (Some(Raw::from(product as i32)), Some(product >> 32)));
        run_with(&mut p, &["-04500260"], &mut UnknownMachine, DOUBLE).unwrap();
        assert_eq!((p.get(10), p.get(11)), (Some(60_000_000), Some(0)));
        // A value that fits 32 bits reads back from the first parameter.
        let mut p = params(&[(1, "-5.")]);
        run_with(&mut p, &["00010060"], &mut UnknownMachine, DOUBLE).unwrap();
        assert_eq!((p.get(10), p.get(11)), (Some(-5_000), Some(-1)));
        // With one half unknown the pair is unknown.
        p.set(11, None);
        run_with(&mut p, &["00600001"], &mut UnknownMachine, DOUBLE).unwrap();
        assert_eq!(p.get(1), None);
        let mut p = params(&[]);
        p.set(11, Some(1 << 40));
        assert_eq!(
            run_with(&mut p, &["00600001"], &mut UnknownMachine, DOUBLE),
            Err((0, ArithError::NotADoubleHalf { parameter: 11, value: 1 << 40 }))
        );
    }

    #[test]
    fn results_must_fit_the_parameter_range() {
        assert_eq!(result(&[(1, "69999.998"), (2, "0.001")], "01010203"), Some(MAX_RAW));
        assert_eq!(error(&[(1, "69999.999"), (2, "0.001")], "01010203"), ArithError::Overflow);
        assert_eq!(error(&[(1, "-69999.999"), (2, "0.001")], "02010203"), ArithError::Overflow);
        assert_eq!(error(&[(1, "300."), (2, "300.")], "03010203"), ArithError::Overflow);
        // A pair holds more.
        let mut p = params(&[(1, "69999.999"), (2, "0.001")]);
        run_with(&mut p, &["01010253"], &mut UnknownMachine, DOUBLE).unwrap();
        assert_eq!((p.get(3), p.get(4)), (Some(70_000_000), Some(0)));
    }

    #[test]
    fn the_failing_word_is_reported_with_its_index() {
        let mut p = params(&[(1, "1")]);
        assert_eq!(run(&mut p, &["00010002", "00010003", "04010004"]), Err((2, ArithError::DivisionByZero)));
        assert_eq!((p.get(2), p.get(3)), (Some(1), Some(1)), "earlier words keep their effects");
    }

    /// Spec 02 §5.7: macro L9001 drills a grid of 4 × 3 holes by rows.
    #[test]
    fn worked_example_l9001() {
        let mut p = params(&[(9, "81"), (10, "100.0"), (11, "75.0"), (12, "4"), (13, "3"), (14, "0")]);
        let block = |p: &mut Parameters, texts: &[&str]| run(p, texts).unwrap();
        // N10: auxiliary parameters.
        for (n, value) in [(15, "0"), (16, "0"), (17, "0"), (18, "31"), (19, "0"), (20, "0")] {
            p.set(n, Some(r(value)));
        }
        // N20: R14 = R17 (0) → R06 = 73, so `N30 GR06 L1105` jumps to drilling by rows.
        block(&mut p, &["19141706"]);
        assert_eq!(p.get(6), Some(73));
        // N1105 G29: save everything, R19 := rows, R12 := R12 − 2, R13 := R13 − 1 (raw integers).
        block(&mut p, &["44000000", "00130019", "-42120212", "-42130113"]);
        assert_eq!([p.get(19), p.get(12), p.get(13)], [Some(3), Some(2), Some(2)]);
        let mut rows = 0;
        loop {
            rows += 1;
            // N1110–N1120: the hole loop runs R12 + 1 times, comparing the row counter each time.
            for _ in 0..=p.get(12).unwrap() {
                block(&mut p, &["19201321"]);
            }
            // N1140 GR21 L1170: all rows done?
            if p.get(21) == Some(73) {
                break;
            }
            // N1160: reverse X, count the row.
            block(&mut p, &["08100010", "-41200020"]);
            assert_eq!(p.get(10), Some(if rows % 2 == 1 { -100_000 } else { 100_000 }));
        }
        assert_eq!((rows, p.get(20)), (3, Some(2)));
        // N1170: three rows are odd, so R17 = 78 and `N1185 GR17 L1200` does not jump.
        block(&mut p, &["47190017"]);
        assert_eq!(p.get(17), Some(78));
        p.set(15, Some(0));
        // N1190: R12 := R12 + 1 = 3 column pitches, R15 := 3 · 100.000, negated.
        block(&mut p, &["-41120012", "-03121015", "08150015"]);
        assert_eq!((p.get(12), p.get(15)), (Some(3), Some(-300_000)));
        // N1200: R14 := 2 · 75.000, negated: the return is X −300, Y −150.
        block(&mut p, &["-03131114", "08140014"]);
        assert_eq!(p.get(14), Some(-150_000));
        // N1230: restore all 96 parameters as saved in N1105.
        block(&mut p, &["45000000"]);
        let restored = [(6, 73), (10, 100_000), (12, 4), (13, 3), (14, 0), (15, 0), (17, 0), (19, 0), (20, 0)];
        for (n, value) in restored {
            assert_eq!(p.get(n), Some(value), "R{n}");
        }
    }

    /// Spec 03 §2.1.3, milling G83 (deep drilling, minus direction), against the trace of Appendix B.
    #[test]
    fn milling_deep_drilling_cycle() {
        let mut p =
            params(&[(26, "460"), (27, "1000"), (28, "12."), (29, "300"), (30, "5."), (31, "-50."), (32, "30.")]);
        let block = |p: &mut Parameters, texts: &[&str]| run(p, texts).unwrap();
        let mut moves = Vec::new();
        // N10: "if R31 > R30 then R24=73"; "abs. hodnota prirustku vrtani".
        block(&mut p, &["15313024", "07280028"]);
        assert_eq!((p.get(24), p.get(28)), (Some(78), Some(12_000)));
        // N40: R29 := R30, R25 := R30; R24=1.000.
        block(&mut p, &["00300029", "00300025"]);
        p.set(24, Some(r("1.000")));
        loop {
            // N50/N60: "if R31 >= R29 then R23 je 73" → end.
            block(&mut p, &["16312923"]);
            if p.get(23) == Some(73) {
                break;
            }
            // N70: rapid to R25, then "R29=R29-R28".
            moves.push(("G00", p.get(25).unwrap()));
            block(&mut p, &["02292829"]);
            // N80/N90: R29 > R31 jumps over N100 (R29=R31, last peck retracts to R32).
            block(&mut p, &["15293123"]);
            if p.get(23) != Some(73) {
                block(&mut p, &["00310029", "00320030"]);
            }
            moves.push(("G01", p.get(29).unwrap()));
            moves.push(("G00", p.get(30).unwrap()));
            // N130: "R25=R29+R24 (R24 = 1mm)".
            block(&mut p, &["01292425"]);
        }
        let expected = [
            ("G00", 5_000),
            ("G01", -7_000),
            ("G00", 5_000),
            ("G00", -6_000),
            ("G01", -19_000),
            ("G00", 5_000),
            ("G00", -18_000),
            ("G01", -31_000),
            ("G00", 5_000),
            ("G00", -30_000),
            ("G01", -43_000),
            ("G00", 5_000),
            ("G00", -42_000),
            ("G01", -50_000),
            ("G00", 30_000),
        ];
        assert_eq!(moves, expected);
    }

    /// Spec 03 §2.3.1, lathe G81 (longitudinal roughing) with example E6: the PROGRAM of N2,
    /// the first chip and the finishing length Zt = −70.635.
    #[test]
    fn lathe_roughing_cycle() {
        let program = [
            "+00280039",
            "+00800085",
            "+31300000",
            "+00020003",
            "+08280028",
            "+22000000",
            "+26010283",
            "+01333333",
            "+01332445",
            "+01453030",
            "+01452811",
            "+01342538",
            "+01383131",
            "+00310044",
            "+00330037",
        ];
        let mut p = params(&[
            (0, "+0"),
            (1, "+1"),
            (2, "+15113010"),
            (3, "+17113010"),
            (24, "-8."),
            (25, "-4."),
            (26, "200"),
            (27, "0.002"),
            (28, "4."),
            (29, "1.678"),
            (30, "-70."),
            (31, "-100."),
        ]);
        for (i, text) in program.iter().enumerate() {
            p.set(7 + i, Some(r(text)));
        }
        // The diameter file reads the radius and doubles it (R33=R33+R33).
        let mut machine = TestMachine { programmed: vec![(1, r("64.")), (2, r("4."))], ..TestMachine::default() };
        let mut block = |p: &mut Parameters, texts: &[&str]| run_with(p, texts, &mut machine, DOUBLE).unwrap();
        block(&mut p, &["+33070021"]);
        let expected = [
            (39, 4_000),   // R39=R28
            (35, -70_000), // R35,R36=R30,R31
            (36, -100_000),
            (3, 15_113_010), // R30 < R00: R03=R02
            (28, -4_000),    // R28=-R28
            (33, 128_000),   // X programmed, doubled
            (34, 4_000),     // Z programmed
            (45, 120_000),   // R45=R33+R24
            (30, 50_000),    // R30=R45+R30
            (11, 116_000),   // R11=R45+R28 (first chip)
            (38, 0),         // R38=R34+R25
            (31, -100_000),  // R31=R38+R31
            (44, -100_000),  // R44=R31
            (37, 128_000),   // R37=R33
        ];
        for (n, value) in expected {
            assert_eq!(p.get(n), Some(value), "R{n}");
        }
        // N50: "R31=R31+R29 Zkraceni" → the first chip ends at Z−98.322.
        block(&mut p, &["+01312931"]);
        assert_eq!(p.get(31), Some(-98_322));
        // N6: R09=R37; the modified instruction R07=R03.
        block(&mut p, &["+00370009", "+00030007"]);
        assert_eq!(p.get(7), Some(15_113_010));
        // N7 G29 runs R05–R08 including the modified R07: "Je-li R11 > R30 pak R10=73".
        let r07 = p.get(7).unwrap().to_string();
        block(&mut p, &["+00110037", "+01112811", &r07, "+00340009"]);
        assert_eq!([p.get(37), p.get(11), p.get(10), p.get(9)], [Some(116_000), Some(112_000), Some(73), Some(4_000)]);
        // N10: R46=0; R27 (2 passes) ≠ 0 → R10=78; R40=abs(R35); R47=R27.
        block(&mut p, &["+02464646", "+19274610", "+07350040", "+00270047"]);
        assert_eq!([p.get(46), p.get(10), p.get(40), p.get(47)], [Some(0), Some(78), Some(70_000), Some(2)]);
        // N11: "R40,41=R29.R40", "R40=R40,41/39", "R09=R44+R40".
        block(&mut p, &["+03294090", "+04903940", "+01444009"]);
        assert_eq!((p.get(40), p.get(9)), (Some(29_365), Some(-70_635)));
        // N15: "R47=R47-R01 dekrement"; "Je-li R47 > R46(0) pak R11=73".
        block(&mut p, &["+00340010", "+02470147", "+15474611"]);
        assert_eq!((p.get(47), p.get(11)), (Some(1), Some(73)));
    }

    /// Spec 03 §2.3.4, lathe G84 (thread cutting): the first chip from the geometric series,
    /// and the Z shift of the alternating infeed.
    #[test]
    fn lathe_thread_cycle() {
        let program = [
            "+00300044",
            "+23290039",
            "+28283940",
            "+07300039",
            "+04394040",
            "+31300000",
            "+08400040",
            "+22000000",
            "+26010283",
            "+01333333",
            "+00800085",
            "+01332411",
            "+01113030",
            "+01114011",
            "+01342538",
        ];
        let mut p = params(&[(0, "+0"), (24, "1."), (25, "2."), (28, "0.8"), (29, "5"), (30, "-1.5"), (31, "-30.")]);
        for (i, text) in program.iter().enumerate() {
            p.set(6 + i, Some(r(text)));
        }
        let mut machine = TestMachine { programmed: vec![(1, r("10.")), (2, r("0."))], ..TestMachine::default() };
        run_with(&mut p, &["+33060020"], &mut machine, DOUBLE).unwrap();
        // "R39=real(R29)", "R40=soucet geometricke rady", "R39=abs(R30)", "R40=R39/R40 = 1. spona", negated.
        assert_eq!([p.get(44), p.get(39), p.get(40)], [Some(-1_500), Some(1_500), Some(-446)]);
        // "R11=R33+R24", "R30=R11+R30 koncova mira", "R11=R11+R40 (prvni triska)".
        assert_eq!([p.get(30), p.get(11)], [Some(19_500), Some(20_554)]);

        // N55/N56 with pitch 1.5 (R41 = 34 × S = 51.000) and cumulative depth R46 = 0.446.
        let mut p =
            params(&[(17, "96.000"), (19, "55.426"), (32, "-1"), (41, "51."), (46, "0.446"), (20, "69999.999")]);
        run(&mut p, &["09463242", "03194245", "07450045", "02414543"]).unwrap();
        // "deli trisku 2 (bin. posun)", "(55.426 x T)", "((34 x S) - (55.426 x T))".
        assert_eq!([p.get(42), p.get(45), p.get(43)], [Some(223), Some(12_360), Some(38_640)]);
        // "Je R20 ruzne od 0?" → "((34 x S) - (55.426 x T))/96 do R20": 0.4025 rounds to 0.403.
        run(&mut p, &["21002018", "04431720", "22000000"]).unwrap();
        assert_eq!(p.get(20), Some(403));
    }

    #[test]
    fn messages_are_written_for_programmers() {
        let samples = [
            (ArithError::UndefinedOperation(43), "operation 43 does not exist (the codes are 00–42 and 44–51)"),
            (
                ArithError::UndocumentedOperation(36),
                "operation 36 (inscribed arc) is not described in the manual, so it cannot be evaluated",
            ),
            (field("op1", 97), "the op1 field holds 97, which is not allowed here"),
            (
                ArithError::InProgram { parameter: 7, error: Box::new(ArithError::DivisionByZero) },
                "in the control word held in R07: division by zero",
            ),
            (
                ArithError::IntegerModeNotAllowed(11),
                "operation 11 works only with real values: write the control word with `+` or without a sign",
            ),
        ];
        for (error, text) in samples {
            assert_eq!(error.to_string(), text);
        }
    }

    /// A small deterministic generator (xorshift), so the test needs no dependency.
    struct Random(u64);

    impl Random {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
        fn value(&mut self) -> Option<Raw> {
            let edges = [0, 1, -1, 73, 1000, -1000, 90_000, MAX_RAW, -MAX_RAW, Raw::MAX, Raw::MIN, 1 << 40];
            match self.below(6) {
                0 => None,
                1 => Some(edges[self.below(edges.len() as u64) as usize]),
                2 => Some(self.below(100_000_000) as Raw * 10 + self.below(100) as Raw),
                3 => Some((self.below(2 * MAX_RAW as u64 + 1) as Raw) - MAX_RAW),
                _ => Some(self.below(2000) as Raw - 1000),
            }
        }
    }

    /// A machine that answers at random.
    struct RandomMachine(std::cell::RefCell<Random>);

    impl Machine for RandomMachine {
        fn measured_position(&self, _axis: u8) -> Option<Raw> {
            self.0.borrow_mut().value()
        }
        fn programmed_position(&self, _axis: u8) -> Option<Raw> {
            self.0.borrow_mut().value()
        }
        fn read_table(&self, _table: u8, _row: u16, _column: u16) -> Option<Raw> {
            self.0.borrow_mut().value()
        }
        fn write_table(&mut self, _table: u8, _row: u16, _column: u16, _value: Raw) {}
        fn message(&mut self, _message: Message) {}
    }

    #[test]
    fn no_input_panics() {
        let mut random = Random(0x9E37_79B9_7F4A_7C15);
        let mut machine = RandomMachine(std::cell::RefCell::new(Random(42)));
        let (mut ok, mut failed) = (0, 0);
        for op in 0..100 {
            for _ in 0..300 {
                let mut p = Parameters::unknown();
                for n in 0..PARAMETER_COUNT {
                    // Some parameters hold control words, so that op 33 has programs to run.
                    let value = if random.below(4) == 0 {
                        Some(random.below(100_000_000) as Raw * if random.below(2) == 0 { 1 } else { -1 })
                    } else {
                        random.value()
                    };
                    p.set(n, value);
                }
                let mut word = || ControlWord {
                    integer: random.below(2) == 0,
                    op,
                    op1: random.below(100) as u8,
                    op2: random.below(100) as u8,
                    target: random.below(100) as u8,
                };
                let words = [word(), word(), word(), word()];
                let len = 1 + (op as usize + words[0].op1 as usize) % 4;
                let config = ArithConfig { double_precision: random.below(2) == 0 };
                match execute(&words[..len], &mut p, &mut machine, config) {
                    Ok(()) => ok += 1,
                    Err((index, _)) => {
                        assert!(index < len);
                        failed += 1;
                    }
                }
            }
        }
        assert!(ok > 1000 && failed > 1000, "{ok} succeeded, {failed} failed");
    }
}
