//! Subprograms and macro calls (lathe manual §6.21 (001:135, 346-348)):
//! M97 P runs the blocks of the same program from block `N<P>`, M98 P the
//! program `O<P>`, G65 P that program as a macro with arguments; each runs
//! until M99 and returns after the calling block, L times.
//!
//! Assumptions the manual does not settle (External: Haas and Fanuc
//! documentation, except where a line is cited):
//! - M97 takes its block number in P, as Haas controls do (the manual
//!   prints `M97 N..`, 001:346, OQ-15), and goes to the first block of the
//!   program with that number.
//! - M98 and G65 find program `O<P>` among the programs of the files read
//!   so far, the calling file's first; else in the file the run's
//!   environment finds for the number ([`Called::Program`]): the program
//!   of that number in it, or its first program.
//! - L repeats the call, L times in all; L0 calls nothing; without L the
//!   call runs once.
//! - G65 assigns its arguments by Fanuc's argument assignments I and II,
//!   which the control tells apart by the letters ([`argument_local`]):
//!   A, B, C are #1–#3; the I, J, K of each set go to the set's three
//!   locals from #4 on (#4–#6, #7–#9, … #31–#33), a set ending where a
//!   letter does not follow the set's last in the order I, J, K; every other
//!   letter has assignment I's local (D #7, E #8, … Z #26). Where two words
//!   give one local, the later in the block holds. Words that are no
//!   argument (G, L, N, O, P) are skipped. Each macro call level has its own
//!   locals #1–#33, vacant but for the arguments, every repetition
//!   starting from them; the caller's come back at M99. M97 and M98 keep
//!   the caller's locals.
//! - `M99 P<n>` returns to the caller's first block numbered n instead of
//!   the block after the call. In the main program `M99 P<n>` goes to block
//!   n, and M99 alone starts the program again on the control: the run
//!   ends there.
//! - A subprogram that reaches its end without M99 stops the run; M02 and
//!   M30 in one end it.
//! - Calls nest at most [`MAX_CALL_DEPTH`] deep, the run's bound against
//!   runaway recursion (the control's own limit is not in the manual).
//! - The block of M97, M98 or M99 makes its move first, then calls or
//!   returns.

use std::sync::Arc;

use ncc_syntax::TextRange;

use super::{Flow, Interpreter, Place, Unit};
use crate::{
    haas_lathe::{eval::Locals, lower::HaasBlock, program::Program},
    trace::{Called, MAX_CALL_DEPTH, RunRule},
};

/// A call being run.
pub(super) struct Call {
    /// Where the caller goes on: the block after the calling one.
    back: Place,
    /// Where the called blocks start, for the repetitions.
    start: Place,
    /// Runs left after the one under way.
    repeats: u32,
    /// G65: the caller's locals, and the arguments every run starts with.
    locals: Option<(Locals, Locals)>,
}

/// Fanuc's argument assignment I: the local each argument letter of G65
/// sets, where assignment II does not give I, J and K theirs.
const ARGUMENTS: [(u8, u32); 21] = [
    (b'A', 1),
    (b'B', 2),
    (b'C', 3),
    (b'I', 4),
    (b'J', 5),
    (b'K', 6),
    (b'D', 7),
    (b'E', 8),
    (b'F', 9),
    (b'H', 11),
    (b'M', 13),
    (b'Q', 17),
    (b'R', 18),
    (b'S', 19),
    (b'T', 20),
    (b'U', 21),
    (b'V', 22),
    (b'W', 23),
    (b'X', 24),
    (b'Y', 25),
    (b'Z', 26),
];

/// The sets of I, J, K assignment II has: #4–#6 up to #31–#33.
const IJK_SETS: u32 = 10;

/// Where the argument words of a G65 block go, word by word.
#[derive(Default)]
struct ArgumentSets {
    /// The I, J, K set under way (0 for #4–#6) and the last of its letters
    /// written (0 for I), if any.
    set: Option<(u32, u32)>,
}

impl ArgumentSets {
    /// The local the argument `letter` sets, in the order the block writes
    /// its words; `None` for a word that is no argument, or an I, J or K
    /// beyond the tenth set.
    fn argument_local(&mut self, letter: u8) -> Option<u32> {
        let Some(offset) = b"IJK".iter().position(|&l| l == letter) else {
            return ARGUMENTS.iter().find(|&&(l, _)| l == letter).map(|&(_, local)| local);
        };
        let offset = offset as u32;
        let set = match self.set {
            Some((set, last)) if offset > last => set,
            Some((set, _)) => set + 1,
            None => 0,
        };
        self.set = Some((set, offset));
        (set < IJK_SETS).then_some(4 + 3 * set + offset)
    }
}

impl Interpreter<'_> {
    /// M97, M98 (`code`) or M99 in the block at `place` of `program`.
    pub(super) fn call_or_return(
        &mut self,
        code: u32,
        place: Place,
        block: &HaasBlock,
        range: TextRange,
        program: &Program,
    ) -> Flow {
        match code {
            97 => {
                let Some(number) = self.target(block, range, "M97", "block") else { return Flow::End };
                match self.numbered(program, number, range, "M97") {
                    Some(start) => self.enter(place, Place { block: start, ..place }, block, range, None),
                    None => Flow::End,
                }
            }
            98 => match self.program_start(block, range, "M98") {
                Some(start) => self.enter(place, start, block, range, None),
                None => Flow::End,
            },
            _ => self.back(block, range, program),
        }
    }

    /// G65 in the block at `place`: the program P with the block's other
    /// words as its arguments.
    pub(super) fn macro_call(&mut self, place: Place, block: &HaasBlock, range: TextRange) -> Flow {
        let mut arguments = Locals::vacant();
        let mut sets = ArgumentSets::default();
        for word in &block.words {
            let Some(local) = sets.argument_local(word.letter) else { continue };
            if let Some(value) = self.word_value(word, range) {
                arguments.set(local, value);
            }
        }
        match self.program_start(block, range, "G65") {
            Some(start) => self.enter(place, start, block, range, Some(arguments)),
            None => Flow::End,
        }
    }

    /// Calls the blocks from `start` from the block at `place`, L times, a
    /// macro call with its `arguments`.
    fn enter(
        &mut self,
        place: Place,
        start: Place,
        block: &HaasBlock,
        range: TextRange,
        arguments: Option<Locals>,
    ) -> Flow {
        let Some(times) = self.repeats(block, range) else { return Flow::End };
        let Some(repeats) = times.checked_sub(1) else { return Flow::Next };
        if self.calls.len() >= MAX_CALL_DEPTH {
            let message = format!("calls nest deeper than {MAX_CALL_DEPTH}: runaway recursion?");
            self.finding(RunRule::CallDepth, range, &message);
            return Flow::End;
        }
        let locals = arguments.map(|arguments| {
            let caller = self.variables.locals();
            self.variables.set_locals(&arguments);
            (caller, arguments)
        });
        self.calls.push(Call { back: Place { block: place.block + 1, ..place }, start, repeats, locals });
        Flow::Go(start)
    }

    /// M99: the next run of the call, or back to the caller.
    fn back(&mut self, block: &HaasBlock, range: TextRange, program: &Program) -> Flow {
        let to = match block.word(b'P') {
            Some(_) => match self.target(block, range, "M99", "block") {
                Some(number) => Some(number),
                None => return Flow::End,
            },
            None => None,
        };
        let Some(call) = self.calls.last_mut() else {
            // The main program: M99 alone starts it again.
            return match to.map(|number| self.numbered(program, number, range, "M99")) {
                Some(Some(block)) => Flow::Jump(block),
                _ => Flow::End,
            };
        };
        if call.repeats > 0 {
            call.repeats -= 1;
            if let Some((_, arguments)) = &call.locals {
                self.variables.set_locals(arguments);
            }
            return Flow::Go(call.start);
        }
        let Some(call) = self.calls.pop() else { return Flow::End };
        if let Some((caller, _)) = &call.locals {
            self.variables.set_locals(caller);
        }
        let Some(number) = to else { return Flow::Go(call.back) };
        let unit = Arc::clone(&self.units[call.back.source]);
        match self.numbered(&unit.model.programs[call.back.program], number, range, "M99") {
            Some(block) => Flow::Go(Place { block, ..call.back }),
            None => Flow::End,
        }
    }

    /// The first block of `program` numbered `number`; `None` after
    /// reporting that there is none.
    fn numbered(&mut self, program: &Program, number: u32, range: TextRange, what: &str) -> Option<usize> {
        let block = program.block_numbers.get(&u64::from(number)).and_then(|blocks| blocks.first()).copied();
        if block.is_none() {
            let message = format!("{what}: there is no block N{number} in the program");
            self.finding(RunRule::CallTargetMissing, range, &message);
        }
        block
    }

    /// Where program `O<P>` of the block starts: in a file read so far, the
    /// calling file's first, or in the file the environment finds; `None`
    /// after reporting that there is none.
    fn program_start(&mut self, block: &HaasBlock, range: TextRange, what: &str) -> Option<Place> {
        let number = self.target(block, range, what, "program")?;
        let numbered = |unit: &Unit| unit.model.programs.iter().position(|program| program.number == Some(number));
        let mut order =
            std::iter::once(self.source).chain((0..self.units.len()).filter(|&source| source != self.source));
        let found = order.find_map(|source| numbered(&self.units[source]).map(|program| (source, program)));
        let called = Called::Program(number);
        // A file read for the number before that does not name it: its first.
        let read = self.called.iter().position(|file| *file == called).map(|index| (index + 1, 0));
        let found = found.or(read).or_else(|| {
            let unit = Unit::read(&self.files.file(&called)?);
            let program = numbered(&unit).unwrap_or(0);
            unit.model.programs.get(program)?;
            self.units.push(Arc::new(unit));
            self.called.push(called);
            Some((self.units.len() - 1, program))
        });
        let Some((source, program)) = found else {
            let message =
                format!("{what}: there is no program O{number} in this file or in a file O{number} beside it");
            self.finding(RunRule::CallTargetMissing, range, &message);
            return None;
        };
        Some(Place { source, program, block: self.units[source].model.programs[program].blocks.start })
    }

    /// The number P of the block names, a whole number; `None` after
    /// reporting that it names none.
    fn target(&mut self, block: &HaasBlock, range: TextRange, what: &str, names: &str) -> Option<u32> {
        let value = block.word(b'P').and_then(|word| self.number(word, range));
        let number = value.filter(|value| value.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(value));
        if number.is_none() {
            let message = format!("{what} needs P, the number of the {names} it goes to, as a whole number");
            self.finding(RunRule::CallTargetMissing, range, &message);
        }
        number.map(|number| number as u32)
    }

    /// How many times the block's call runs: L, or once without it; `None`
    /// after reporting an L that is no count.
    fn repeats(&mut self, block: &HaasBlock, range: TextRange) -> Option<u32> {
        let Some(word) = block.word(b'L') else { return Some(1) };
        let value = self.number(word, range);
        let times = value.filter(|value| value.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(value));
        if times.is_none() {
            let message = "L, the number of times the call runs, is a whole number from 0";
            self.finding(RunRule::ValueRefused, range, message);
        }
        times.map(|times| times as u32)
    }
}
