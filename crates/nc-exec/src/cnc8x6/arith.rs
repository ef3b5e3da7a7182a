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
    cnc8x6::lower::{BlockData, Value},
    machine::MachineConfig,
    trace::{Message, MessageDisplay},
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
mod tests;
