//! Calls and returns (digest §2.7): programs by name with their PROC
//! parameters, repetitions, SAVE, MCALL and program sections, and the
//! predefined procedures the run carries out itself (MSG, WRITE, READ,
//! DELETE; GROUP_BEGIN, GROUP_END and WORKPIECE are markers for the editor
//! and the simulation and do nothing).

use std::sync::Arc;

use ncc_syntax::TextRange;

use super::{At, Flow, Interpreter, Unit, files::DONE};
use crate::{
    sinumerik::{
        eval::{Slot, Value},
        lower::{Call, Callee, Expr, ExprKind, Place, PlaceKind, Type, WordValue, control_files},
        program::PROGRAM_LEVELS,
    },
    trace::{Called, RunRule},
};

/// A call being run, or a program section REPEAT runs.
pub(super) struct Frame {
    /// Where the caller goes on.
    back: At,
    /// The first block of the called program or section.
    start: At,
    /// Runs left after the one under way.
    repeats: u64,
    /// The formal parameters' bindings; `None` for a section, which runs
    /// in its program's scope.
    bound: Option<Vec<Bound>>,
    passed: Vec<bool>,
    /// SAVE: the caller's modes, which come back with the return.
    saved: Option<super::Modes>,
    /// Called by MCALL: no modal call from inside it.
    pub(super) modal: bool,
    /// A section's last block.
    section_end: Option<usize>,
}

/// A formal parameter's binding.
#[derive(Clone)]
enum Bound {
    Value { name: String, ty: Type, value: Option<Value> },
    Alias { name: String, slot: Slot },
}

impl Interpreter<'_> {
    /// Runs the call in the block at `at`.
    pub(super) fn call(&mut self, at: At, call: &Call, range: TextRange) -> Flow {
        let name = match &call.callee {
            Callee::Predefined(name) => return self.predefined(name, &call.arguments, range),
            Callee::Cycle(name) => {
                self.cycle(at, name, &call.arguments, range);
                return Flow::Next;
            }
            Callee::Program(name) | Callee::Path(name) => name.clone(),
            Callee::Numbered { letter: b'L', number: Some(number) } => format!("L{number}"),
            Callee::Numbered { letter, .. } => {
                self.state.not_run(&format!("subprograms called by {}", char::from(*letter)), range);
                return Flow::Next;
            }
            Callee::Indirect { section: Some(_), .. } => {
                self.state.not_run("CALL … BLOCK sections", range);
                return Flow::Next;
            }
            Callee::Indirect { program, section: None } => {
                let result = self.eval().value(program);
                match self.check(result) {
                    Some(name) => name.text(),
                    None => return Flow::Stop,
                }
            }
        };
        let runs = match call.repetitions.as_deref() {
            None => 1.0,
            Some(WordValue::Literal(number)) => number.value(),
            Some(WordValue::Expr { expr, .. }) => {
                let result = self.eval().number(expr);
                match self.check(result) {
                    Some(runs) => runs,
                    None => return Flow::Stop,
                }
            }
        };
        if !(runs >= 0.0 && runs.fract() == 0.0) {
            self.state.finding(RunRule::ValueRefused, range, "P, the repetitions, is a whole number from 0");
            return Flow::Stop;
        }
        if runs == 0.0 {
            return Flow::Next;
        }
        self.enter(at, &name, &call.arguments, runs as u64 - 1, false, range)
    }

    /// MCALL's program after a block with a path motion, its arguments
    /// evaluated anew at each call.
    pub(super) fn modal(&mut self, at: At, modal: &Call, range: TextRange) -> Flow {
        match &modal.callee {
            Callee::Cycle(name) => {
                self.cycle(at, name, &modal.arguments, range);
                Flow::Next
            }
            callee => match callee.program_name() {
                Some(name) => self.enter(at, name, &modal.arguments, 0, true, range),
                None => {
                    self.state.not_run("this modal call", range);
                    Flow::Next
                }
            },
        }
    }

    /// Calls program `name` from the block at `at` with `arguments`, to
    /// run `repeats` more times after the first.
    fn enter(
        &mut self,
        at: At,
        name: &str,
        arguments: &[Option<Expr>],
        repeats: u64,
        modal: bool,
        range: TextRange,
    ) -> Flow {
        let Some(source) = self.program(name) else {
            let message = format!("no program {name} to call: not written by the run, nor beside the program");
            self.state.finding(RunRule::CallTargetMissing, range, &message);
            return Flow::Stop;
        };
        if self.calls.iter().filter(|frame| frame.bound.is_some()).count() + 1 >= PROGRAM_LEVELS {
            let message = format!("calls nested deeper than the control's {PROGRAM_LEVELS} program levels");
            self.state.finding(RunRule::CallDepth, range, &message);
            return Flow::Stop;
        }
        let unit = Arc::clone(&self.units[source]);
        if unit.count() == 0 {
            // An empty file does nothing, however often it runs.
            return Flow::Next;
        }
        let header = unit.model.header().map(|proc| &proc.declaration);
        let parameters = header.map_or(&[][..], |proc| &proc.parameters[..]);
        if arguments.len() > parameters.len() {
            let message = format!("{name} takes {} parameters, the call gives {}", parameters.len(), arguments.len());
            self.state.finding(RunRule::ValueRefused, range, &message);
            return Flow::Stop;
        }
        let mut bound = Vec::with_capacity(parameters.len());
        for (index, parameter) in parameters.iter().enumerate() {
            let Some(formal) = parameter.name.clone() else { continue };
            let actual = arguments.get(index).and_then(Option::as_ref);
            if parameter.by_reference {
                let slot = match actual.map(|actual| &actual.kind) {
                    Some(ExprKind::Name(place)) => {
                        let result = self.eval().slot(place, range);
                        self.check(result)
                    }
                    _ => {
                        let message = format!("{formal} is passed by reference (VAR): the call must name a variable");
                        self.state.finding(RunRule::ValueRefused, range, &message);
                        None
                    }
                };
                let Some(slot) = slot else { return Flow::Stop };
                bound.push(Bound::Alias { name: formal, slot });
            } else {
                let value = match actual {
                    Some(actual) => {
                        let result = self.eval().value(actual);
                        match self.check(result) {
                            Some(value) => Some(value),
                            None => return Flow::Stop,
                        }
                    }
                    None => None,
                };
                bound.push(Bound::Value { name: formal, ty: parameter.ty.clone(), value });
            }
        }
        let passed = (0..parameters.len()).map(|index| arguments.get(index).is_some_and(Option::is_some)).collect();
        let saved = header.filter(|proc| proc.attributes.iter().any(|a| a == "SAVE")).map(|_| self.state.modes.clone());
        let frame = Frame {
            back: At { block: at.block + 1, ..at },
            start: At { source, block: 0 },
            repeats,
            bound: Some(bound),
            passed,
            saved,
            modal,
            section_end: None,
        };
        if !self.open_scope(&frame, range) {
            return Flow::Stop;
        }
        self.calls.push(frame);
        Flow::Go(At { source, block: 0 })
    }

    /// The parameters of the PROC line of the program being run by
    /// itself: zero, as if a call left them all out.
    pub(super) fn bind_own_parameters(&mut self) {
        let unit = Arc::clone(&self.units[0]);
        let Some(header) = unit.model.header() else { return };
        self.state.block_start = unit.ranges[header.block].start();
        for parameter in &header.declaration.parameters {
            let Some(name) = &parameter.name else { continue };
            let result = self.eval().bind_value(name, &parameter.ty, None, parameter.range);
            self.check(result);
        }
    }

    /// Opens the scope of a call's run with its parameters bound; false
    /// after reporting a value that does not fit its parameter.
    fn open_scope(&mut self, frame: &Frame, range: TextRange) -> bool {
        let Some(bound) = &frame.bound else { return true };
        self.store.push_scope(frame.passed.clone());
        for binding in bound {
            match binding {
                Bound::Alias { name, slot } => self.store.alias(name, *slot),
                Bound::Value { name, ty, value } => {
                    let result = self.eval().bind_value(name, ty, value.clone(), range);
                    if self.check(result).is_none() {
                        return false;
                    }
                }
            }
        }
        true
    }

    /// The source of the program `name`: a file the run wrote, one it
    /// read, or one the environment finds, MPF before SPF.
    fn program(&mut self, name: &str) -> Option<usize> {
        for file in control_files(name) {
            if let Some(written) = self.state.files.program(&file) {
                let (path, text) = (written.path.clone(), written.text.clone());
                return Some(self.unit_of(Called::Written(path), &text));
            }
            let called = Called::ControlFile(file);
            if let Some(index) = self.called.iter().position(|c| *c == called) {
                return Some(index + 1);
            }
            if let Some(text) = self.files.file(&called) {
                return Some(self.unit_of(called, &text));
            }
        }
        None
    }

    /// The source of a file read as `called` with `text`: the one already
    /// lowered for a file read before with the same text, else a new one.
    pub(super) fn unit_of(&mut self, called: Called, text: &str) -> usize {
        let unchanged = |interpreter: &Self, index: usize| {
            interpreter.called[index] == called && !matches!(called, Called::Written(_))
        };
        if let Some(index) = (0..self.called.len()).find(|&index| unchanged(self, index)) {
            return index + 1;
        }
        self.units.push(Arc::new(Unit::read(text, self.files)));
        self.called.push(called);
        self.units.len() - 1
    }

    /// The block after the called program returns (RET, M17, its end);
    /// `None` at the main program's end.
    pub(super) fn return_from(&mut self) -> Option<At> {
        self.end_spline();
        while self.calls.last().is_some_and(|frame| frame.bound.is_none()) {
            self.calls.pop();
        }
        let frame = self.calls.last_mut()?;
        if frame.repeats > 0 {
            frame.repeats -= 1;
            let start = frame.start;
            let (bound, passed) = (frame.bound.clone(), frame.passed.clone());
            self.store.pop_scope();
            let again =
                Frame { back: start, start, repeats: 0, bound, passed, saved: None, modal: false, section_end: None };
            if !self.open_scope(&again, TextRange::default()) {
                return None;
            }
            return Some(start);
        }
        let frame = self.calls.pop()?;
        self.store.pop_scope();
        if let Some(saved) = frame.saved {
            self.state.modes.restore_g(&saved);
        }
        Some(frame.back)
    }

    /// `next`, or where a program section that the block at `at` ends
    /// goes on: its start again, or after its REPEAT.
    pub(super) fn section_end(&mut self, at: At, next: At) -> At {
        let Some(frame) = self.calls.last_mut() else { return next };
        let ends = frame.section_end == Some(at.block)
            && frame.start.source == at.source
            && next == At { block: at.block + 1, ..at };
        if !ends {
            return next;
        }
        if frame.repeats > 0 {
            frame.repeats -= 1;
            return frame.start;
        }
        let back = frame.back;
        self.calls.pop();
        back
    }

    /// `REPEAT start [end] P=n` in the block at `at`: the section from the
    /// label `start` before it to the label `end` (or the block `start`
    /// alone), n times (1 without P), then the block after.
    pub(super) fn repeat_section(
        &mut self,
        at: At,
        unit: &Unit,
        start: &str,
        end: Option<&str>,
        count: Option<&Expr>,
        range: TextRange,
    ) -> Flow {
        let runs = match count {
            Some(count) => {
                let result = self.eval().number(count);
                match self.check(result) {
                    Some(runs) if runs >= 0.0 && runs.fract() == 0.0 => runs as u64,
                    Some(_) => {
                        self.state.finding(
                            RunRule::ValueRefused,
                            range,
                            "P, the repetitions, is a whole number from 0",
                        );
                        return Flow::Stop;
                    }
                    None => return Flow::Stop,
                }
            }
            None => 1,
        };
        let labelled = |label: &str| unit.model.labels.get(label).map_or(&[][..], |blocks| blocks.as_slice());
        let first = labelled(start).iter().rev().copied().find(|&block| block < at.block);
        let last = match (first, end) {
            (Some(first), Some(end)) => labelled(end).iter().copied().find(|&block| block >= first && block < at.block),
            (first, None) => first,
            (None, Some(_)) => None,
        };
        let (Some(first), Some(last)) = (first, last) else {
            let message = "REPEAT's labels are not in the program before it: the control stops";
            self.state.finding(RunRule::CallTargetMissing, range, message);
            return Flow::Stop;
        };
        if runs == 0 {
            return Flow::Next;
        }
        if self.calls.len() >= u16::MAX as usize {
            self.state.finding(RunRule::CallDepth, range, "program sections nested without end");
            return Flow::Stop;
        }
        let start = At { block: first, ..at };
        self.calls.push(Frame {
            back: At { block: at.block + 1, ..at },
            start,
            repeats: runs - 1,
            bound: None,
            passed: Vec::new(),
            saved: None,
            modal: false,
            section_end: Some(last),
        });
        Flow::Go(start)
    }

    /// A predefined procedure.
    fn predefined(&mut self, name: &str, arguments: &[Option<Expr>], range: TextRange) -> Flow {
        let mut values = Vec::with_capacity(arguments.len());
        // The first of WRITE, READ and DELETE is the error variable, the
        // last of READ the array it reads into: places, not values.
        let places = match name {
            "WRITE" | "DELETE" => 1..arguments.len(),
            "READ" => 1..4,
            _ => 0..arguments.len(),
        };
        for (index, argument) in arguments.iter().enumerate() {
            let value = match argument {
                Some(expr) if places.contains(&index) => {
                    let result = self.eval().value(expr);
                    match self.check(result) {
                        Some(value) => Some(value),
                        None => return Flow::Stop,
                    }
                }
                _ => None,
            };
            values.push(value);
        }
        let text = |index: usize| values.get(index).and_then(Option::as_ref).map(Value::text);
        let code = match name {
            "MSG" | "GROUP_BEGIN" | "GROUP_END" | "WORKPIECE" => return Flow::Next,
            "WRITE" => match (text(1), text(2)) {
                (Some(path), Some(line)) => self.state.files.write(&path, &line),
                _ => return self.missing(name, range),
            },
            "DELETE" => match text(1) {
                Some(path) => self.state.files.delete(&path),
                None => return self.missing(name, range),
            },
            "READ" => {
                let number = |index: usize| values.get(index).and_then(Option::as_ref).map(|v| v.int(range));
                match (text(1), number(2), number(3)) {
                    (Some(path), Some(Ok(first)), Some(Ok(count))) => {
                        match self.state.files.read(&path, first, count) {
                            Ok(lines) => {
                                match self.read_into(arguments.get(4).and_then(Option::as_ref), lines, range) {
                                    Some(()) => DONE,
                                    None => return Flow::Stop,
                                }
                            }
                            Err(code) => code,
                        }
                    }
                    _ => return self.missing(name, range),
                }
            }
            _ => {
                self.state.not_run(&format!("the procedure {name}"), range);
                return Flow::Next;
            }
        };
        let Some(Some(Expr { kind: ExprKind::Name(error), .. })) = arguments.first() else {
            return self.missing(name, range);
        };
        let result = self.eval().write(error, Value::Int(code), range);
        if self.check(result).is_some() { Flow::Next } else { Flow::Stop }
    }

    /// READ's lines into the array `target` names, from its first element.
    fn read_into(&mut self, target: Option<&Expr>, lines: Vec<String>, range: TextRange) -> Option<()> {
        let Some(Expr { kind: ExprKind::Name(place), .. }) = target else {
            self.missing("READ", range);
            return None;
        };
        for (index, line) in lines.into_iter().enumerate() {
            let element = Expr { kind: ExprKind::Integer(index as i64), range };
            let place = Place { kind: PlaceKind::User, name: place.name.clone(), indices: vec![element] };
            let result = self.eval().write(&place, Value::Str(line), range);
            self.check(result)?;
        }
        Some(())
    }

    fn missing(&mut self, name: &str, range: TextRange) -> Flow {
        let signature = ncc_catalog::Dialect::Sinumerik.catalogue().function(name).map(|f| f.signature());
        let message = format!("{name} lacks an argument: {}", signature.unwrap_or_default());
        self.state.finding(RunRule::ValueRefused, range, &message);
        Flow::Stop
    }
}
