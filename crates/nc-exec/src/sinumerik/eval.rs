//! Sinumerik values and expressions: the typed values a program computes
//! with (digest §2.3, §2.4, §2.6), the variables that hold them and the
//! evaluation of the lowered expression trees, whose operator order the
//! parser already settled.
//!
//! The variables ([`Store`]): the R parameters (`R5`, `R[expr]`; how
//! many a control has is machine data, `$MN_MM_NUM_R_PARAM`, which the
//! run does not know, and real programs use R999: every index below
//! [`R_PARAMETER_LIMIT`] runs, the store growing to the highest written),
//! the names DEF declares with their type and array dimensions, in
//! scopes (a subprogram's DEFs are its own; a `VAR` formal parameter
//! aliases the caller's variable or array element), and global user data
//! (GUD), which the run creates when a program uses a name nothing
//! declares. System variables (`$…`) and `G[n]` belong to the run, which
//! answers them through [`Context`].
//!
//! Conversions and arithmetic (Siemens documentation where the digest's
//! seed is silent; each an assumption of this module):
//! - A number written without a point or exponent is an INT, any other a
//!   REAL; `+ - *` of two INTs is an INT (an overflow is an error), `/`
//!   always gives a REAL, `DIV` an INT (truncated), `MOD` an INT of INTs
//!   and a REAL otherwise (the remainder's sign is the dividend's).
//! - REAL to INT rounds half away from zero (assignment, an INT
//!   parameter, an index); REAL, INT, CHAR to BOOL is "not zero"; STRING to
//!   BOOL is "not empty"; BOOL to a number is 1 or 0.
//! - `<<` and STRING conversion write a whole REAL without decimals
//!   (`"N"<<R3` with R3 = 1632 is `N1632`, 004:4629-4633, 5047) and any
//!   other as the shortest decimal that reads back as the same value
//!   (`0.1`, `-2.0790939`); an INT as its digits, a BOOL as `1` or `0`, a
//!   CHAR as its character, an AXIS as its name.
//! - A STRING ends at its first NUL (004:1688-1690); a `STRING[n]`
//!   variable keeps at most n bytes.
//! - REAL equality is relative: two values are equal when they differ by
//!   at most 1e-12 times the larger magnitude (Siemens compares REALs
//!   relatively; the digest gives no epsilon), so that
//!   `VAC_POLE[i,1]==VAC_POLE[i+1,1]` (004:5091) holds for values a
//!   rounding apart.
//! - Trigonometric functions take and give degrees.
//! - Functions of the catalogue without a computable meaning in a run
//!   (procedures like `WRITE`, which the run does itself, or `GETSELT`)
//!   give an error that says they are not modelled, not a guess.
//! - An array a program uses without a definition the run sees (a GUD
//!   whose definition file is not in the project) is a REAL array of the
//!   dimensions the first use indexes, each [`OPEN_ARRAY_SIZE`] long for
//!   one or two indices and smaller beyond, so that it holds 10 000
//!   values; the run reports that it assumes so.

use std::collections::HashMap;

use ncc_catalog::Dialect;
use ncc_syntax::TextRange;

use super::lower::{BaseType, BinaryOp, Declared, Expr, ExprKind, Place, PlaceKind, Type, UnaryOp};

/// A value of the language.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Int(i64),
    Real(f64),
    Bool(bool),
    Char(u8),
    Str(String),
    /// An axis by its name (`X`, `A2`).
    Axis(String),
}

/// Why an expression has no value.
#[derive(Debug, Clone, PartialEq)]
pub struct EvalError {
    pub kind: ErrorKind,
    pub message: String,
    /// Relative to the block, as the expression's.
    pub range: TextRange,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// The control stops with an alarm (a division by zero, a wrong type).
    Failed,
    /// The run does not model what the expression asks for.
    NotModelled,
}

type Result<T> = std::result::Result<T, EvalError>;

fn failed(range: TextRange, message: impl Into<String>) -> EvalError {
    EvalError { kind: ErrorKind::Failed, message: message.into(), range }
}

fn not_modelled(range: TextRange, message: impl Into<String>) -> EvalError {
    EvalError { kind: ErrorKind::NotModelled, message: message.into(), range }
}

/// The relative tolerance of REAL equality.
const REAL_EQUALITY: f64 = 1e-12;

/// The length of each dimension of an undefined one- or two-dimensional
/// array (see the module documentation).
pub const OPEN_ARRAY_SIZE: usize = 100;

/// The most elements an undefined array holds.
const OPEN_ARRAY_ELEMENTS: usize = OPEN_ARRAY_SIZE * OPEN_ARRAY_SIZE;

/// The most elements a DEF'd array may have: a larger one is refused
/// rather than allocated.
const MAX_ARRAY_ELEMENTS: usize = 1 << 20;

impl Value {
    /// The value written as text, as `<<` writes it.
    pub fn text(&self) -> String {
        match self {
            Value::Int(value) => value.to_string(),
            Value::Real(value) => real_text(*value),
            Value::Bool(value) => if *value { "1" } else { "0" }.to_owned(),
            Value::Char(byte) => char::from(*byte).to_string(),
            Value::Str(text) | Value::Axis(text) => text.clone(),
        }
    }

    /// The value as a number, for arithmetic and addresses.
    pub fn number(&self, range: TextRange) -> Result<f64> {
        match self {
            Value::Int(value) => Ok(*value as f64),
            Value::Real(value) => Ok(*value),
            Value::Bool(value) => Ok(f64::from(u8::from(*value))),
            Value::Char(byte) => Ok(f64::from(*byte)),
            Value::Str(text) => {
                parse_number(text).ok_or_else(|| failed(range, format!("the string \"{text}\" is not a number")))
            }
            Value::Axis(name) => Err(failed(range, format!("the axis {name} is not a number"))),
        }
    }

    /// The value as an INT: a REAL rounded half away from zero.
    pub fn int(&self, range: TextRange) -> Result<i64> {
        match self {
            Value::Int(value) => Ok(*value),
            other => {
                let value = other.number(range)?.round();
                if value.is_finite() && value.abs() < 9.2e18 {
                    Ok(value as i64)
                } else {
                    Err(failed(range, "a value too large for an INT"))
                }
            }
        }
    }

    /// The value as a condition.
    pub fn truth(&self, range: TextRange) -> Result<bool> {
        match self {
            Value::Bool(value) => Ok(*value),
            Value::Int(value) => Ok(*value != 0),
            Value::Real(value) => Ok(*value != 0.0),
            Value::Char(byte) => Ok(*byte != 0),
            Value::Str(text) => Ok(!text.is_empty()),
            Value::Axis(name) => Err(failed(range, format!("the axis {name} is no condition"))),
        }
    }

    /// The value converted to `ty` for a variable of that type, a string
    /// cut to `length` bytes.
    pub fn convert(self, ty: &BaseType, length: Option<usize>, range: TextRange) -> Result<Value> {
        Ok(match ty {
            BaseType::Int => Value::Int(self.int(range)?),
            BaseType::Real => Value::Real(self.number(range)?),
            BaseType::Bool => Value::Bool(self.truth(range)?),
            BaseType::Char => match self {
                Value::Str(text) if text.len() == 1 => Value::Char(text.as_bytes()[0]),
                Value::Char(byte) => Value::Char(byte),
                other => {
                    let code = other.int(range)?;
                    Value::Char(u8::try_from(code).map_err(|_| failed(range, format!("{code} is no CHAR")))?)
                }
            },
            BaseType::String => {
                let mut text = string_value(self.text());
                if let Some(length) = length {
                    truncate_at_char(&mut text, length);
                }
                Value::Str(text)
            }
            BaseType::Axis => match self {
                Value::Axis(name) | Value::Str(name) => Value::Axis(name.to_ascii_uppercase()),
                other => return Err(failed(range, format!("{} is no axis", other.text()))),
            },
            BaseType::Frame | BaseType::Unknown => return Err(not_modelled(range, "FRAME variables")),
        })
    }

    /// The value every element of a variable of `ty` starts with.
    pub fn zero(ty: &BaseType) -> Value {
        match ty {
            BaseType::Int => Value::Int(0),
            BaseType::Bool => Value::Bool(false),
            BaseType::Char => Value::Char(0),
            BaseType::String => Value::Str(String::new()),
            BaseType::Axis => Value::Axis(String::new()),
            BaseType::Real | BaseType::Frame | BaseType::Unknown => Value::Real(0.0),
        }
    }
}

/// A REAL as `<<` writes it (see the module documentation).
pub fn real_text(value: f64) -> String {
    if value == 0.0 {
        return "0".to_owned();
    }
    if value.fract() == 0.0 && value.abs() < 1e15 {
        return format!("{value:.0}");
    }
    format!("{value}")
}

/// A string as the control keeps it: up to its first NUL.
fn string_value(mut text: String) -> String {
    if let Some(nul) = text.find('\0') {
        text.truncate(nul);
    }
    text
}

fn truncate_at_char(text: &mut String, length: usize) {
    if text.len() > length {
        let mut end = length;
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        text.truncate(end);
    }
}

/// A string's number, as NUMBER reads it: optional sign, digits, point,
/// `EX` exponent; spaces around allowed.
fn parse_number(text: &str) -> Option<f64> {
    let trimmed = text.trim();
    let normal = trimmed.to_ascii_uppercase().replace("EX", "E");
    let plausible = !normal.is_empty()
        && normal.bytes().all(|b| b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'E'))
        && normal.bytes().any(|b| b.is_ascii_digit());
    plausible.then(|| normal.parse::<f64>().ok()).flatten().filter(|value| value.is_finite())
}

/// What the run answers for the expressions: its system variables, its
/// group codes and its files.
pub trait Context {
    /// The value of system variable `name` (upper case, with `$`) at
    /// `indices`.
    fn system(&mut self, name: &str, indices: &[Value], range: TextRange) -> Result<Value>;
    /// Writes system variable `name` at `indices`.
    fn write_system(&mut self, name: &str, indices: &[Value], value: Value, range: TextRange) -> Result<()>;
    /// `G[group]=index`: puts the code of that index in its group in force.
    fn set_group(&mut self, group: i64, index: i64, range: TextRange) -> Result<()>;
    /// Whether the file `path` exists (ISFILE).
    fn is_file(&self, path: &str) -> bool;
    /// Reports once that an array is used without a definition.
    fn undefined_array(&mut self, name: &str, range: TextRange);
}

/// A variable: its type, dimensions and values, row-major.
#[derive(Debug, Clone, PartialEq)]
struct Variable {
    ty: BaseType,
    /// `STRING[n]`: at most n bytes.
    length: Option<usize>,
    dimensions: Vec<usize>,
    values: Vec<Value>,
}

/// Where a variable is: a global (GUD) or a local of a scope.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Cell {
    Global(usize),
    Local(usize),
    /// An R parameter, by its number.
    Parameter(usize),
}

/// A variable, or one element of an array, that a name stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slot {
    cell: Cell,
    /// One element of an array (a `VAR` parameter bound to `A[1,2]`).
    element: Option<usize>,
}

/// The names of one program level.
#[derive(Debug, Clone, Default, PartialEq)]
struct Scope {
    names: HashMap<String, Slot>,
    /// The first of its own locals in [`Store::locals`].
    first_local: usize,
    /// Which formal parameters the call passed (`$P_SUBPAR[n]`).
    passed: Vec<bool>,
}

/// Every variable of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Store {
    parameters: Vec<f64>,
    globals: Vec<Variable>,
    global_names: HashMap<String, usize>,
    locals: Vec<Variable>,
    /// Innermost last; the main program's is the first.
    scopes: Vec<Scope>,
}

/// One past the highest R parameter a run takes: a bound on the memory a
/// computed index can claim, far above any machine's count (assumption).
pub const R_PARAMETER_LIMIT: usize = 65_536;

impl Default for Store {
    fn default() -> Self {
        Store::new()
    }
}

impl Store {
    /// The R parameters of the catalogue's standard count, all 0, and the
    /// main program's empty scope.
    pub fn new() -> Store {
        let count = Dialect::Sinumerik.catalogue().parameters.count as usize;
        Store {
            parameters: vec![0.0; count],
            globals: Vec::new(),
            global_names: HashMap::new(),
            locals: Vec::new(),
            scopes: vec![Scope::default()],
        }
    }

    /// Enters a called program's scope, which `passed` says which formal
    /// parameters the call gave.
    pub fn push_scope(&mut self, passed: Vec<bool>) {
        self.scopes.push(Scope { names: HashMap::new(), first_local: self.locals.len(), passed });
    }

    /// Leaves the innermost called program's scope, dropping its locals.
    pub fn pop_scope(&mut self) {
        if self.scopes.len() > 1
            && let Some(scope) = self.scopes.pop()
        {
            self.locals.truncate(scope.first_local);
        }
    }

    /// Whether the call of the innermost scope passed parameter `number`
    /// (from 1).
    pub fn passed(&self, number: i64) -> bool {
        let scope = self.scopes.last();
        usize::try_from(number - 1).ok().and_then(|index| scope?.passed.get(index).copied()).unwrap_or(false)
    }

    /// Whether `name` is a variable the innermost scope sees.
    pub fn is_defined(&self, name: &str) -> bool {
        self.lookup(name).is_some()
    }

    fn lookup(&self, name: &str) -> Option<Slot> {
        let local = self.scopes.last().and_then(|scope| scope.names.get(name)).copied();
        local.or_else(|| self.global_names.get(name).map(|&index| Slot { cell: Cell::Global(index), element: None }))
    }

    /// The variable at `cell`; `None` for an R parameter.
    fn variable(&self, cell: Cell) -> Option<&Variable> {
        match cell {
            Cell::Global(index) => Some(&self.globals[index]),
            Cell::Local(index) => Some(&self.locals[index]),
            Cell::Parameter(_) => None,
        }
    }

    /// Declares `name` in the innermost scope (a DEF, or a formal
    /// parameter by value), or as global user data, every element zero.
    fn declare(
        &mut self,
        name: &str,
        ty: BaseType,
        length: Option<usize>,
        dimensions: Vec<usize>,
        global: bool,
    ) -> Slot {
        let size = dimensions.iter().product::<usize>().max(1);
        let variable = Variable { values: vec![Value::zero(&ty); size], ty, length, dimensions };
        if global {
            self.globals.push(variable);
            self.global_names.insert(name.to_owned(), self.globals.len() - 1);
            return Slot { cell: Cell::Global(self.globals.len() - 1), element: None };
        }
        self.locals.push(variable);
        let slot = Slot { cell: Cell::Local(self.locals.len() - 1), element: None };
        if let Some(scope) = self.scopes.last_mut() {
            scope.names.insert(name.to_owned(), slot);
        }
        slot
    }

    /// Binds `name` in the innermost scope to `slot`, a variable of a
    /// caller (a `VAR` parameter).
    pub fn alias(&mut self, name: &str, slot: Slot) {
        if let Some(scope) = self.scopes.last_mut() {
            scope.names.insert(name.to_owned(), slot);
        }
    }

    fn read(&self, slot: Slot) -> Value {
        match slot.cell {
            Cell::Parameter(index) => Value::Real(self.parameters[index]),
            Cell::Global(index) => self.globals[index].values[slot.element.unwrap_or(0)].clone(),
            Cell::Local(index) => self.locals[index].values[slot.element.unwrap_or(0)].clone(),
        }
    }

    fn write(&mut self, slot: Slot, value: Value, range: TextRange) -> Result<()> {
        let variable = match slot.cell {
            Cell::Parameter(index) => {
                self.parameters[index] = value.number(range)?;
                return Ok(());
            }
            Cell::Global(index) => &mut self.globals[index],
            Cell::Local(index) => &mut self.locals[index],
        };
        let value = value.convert(&variable.ty, variable.length, range)?;
        variable.values[slot.element.unwrap_or(0)] = value;
        Ok(())
    }

    /// The R parameter `index`.
    pub fn parameter(&self, index: usize) -> Option<f64> {
        self.parameters.get(index).copied()
    }
}

/// Evaluates expressions over a run's variables and its context.
pub struct Eval<'a> {
    pub store: &'a mut Store,
    pub context: &'a mut dyn Context,
}

impl std::fmt::Debug for Eval<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Eval").field("store", &self.store).finish_non_exhaustive()
    }
}

impl Eval<'_> {
    /// The value of `expr`.
    pub fn value(&mut self, expr: &Expr) -> Result<Value> {
        let range = expr.range;
        match &expr.kind {
            ExprKind::Number(number) => {
                let whole = !number.decimal.has_point() && number.exponent == 0;
                let value = number.value();
                Ok(if whole && value.abs() < 9.0e15 { Value::Int(value as i64) } else { Value::Real(value) })
            }
            ExprKind::String(text) => Ok(Value::Str(string_value(text.clone()))),
            ExprKind::Bool(value) => Ok(Value::Bool(*value)),
            ExprKind::Integer(value) => Ok(Value::Int(*value)),
            ExprKind::Name(place) => self.read(place, range),
            ExprKind::Call { name, arguments } => self.call(name, arguments, range),
            ExprKind::Unary(op, operand) => {
                let value = self.value(operand)?;
                unary(*op, value, range)
            }
            ExprKind::Binary(op, lhs, rhs) => {
                let (lhs, rhs) = (self.value(lhs)?, self.value(rhs)?);
                binary(*op, lhs, rhs, range)
            }
            ExprKind::List(_) => Err(failed(range, "a list of values is only an array's initial values")),
            ExprKind::Malformed => Err(failed(range, "a malformed expression")),
        }
    }

    /// The number `expr` gives.
    pub fn number(&mut self, expr: &Expr) -> Result<f64> {
        let value = self.value(expr)?;
        value.number(expr.range)
    }

    /// Whether the condition `expr` holds.
    pub fn truth(&mut self, expr: &Expr) -> Result<bool> {
        let value = self.value(expr)?;
        value.truth(expr.range)
    }

    fn indices(&mut self, place: &Place) -> Result<Vec<Value>> {
        place.indices.iter().map(|index| self.value(index)).collect()
    }

    fn read(&mut self, place: &Place, range: TextRange) -> Result<Value> {
        match place.kind {
            PlaceKind::Parameter => {
                let index = self.parameter_index(place, range)?;
                Ok(Value::Real(self.store.parameters[index]))
            }
            PlaceKind::System if place.name == "$P_SUBPAR" => {
                let number = match place.indices.first() {
                    Some(index) => self.value(index)?.int(index.range)?,
                    None => return Err(failed(range, "$P_SUBPAR needs the parameter's number")),
                };
                Ok(Value::Bool(self.store.passed(number)))
            }
            PlaceKind::System => {
                let indices = self.indices(place)?;
                self.context.system(&place.name, &indices, range)
            }
            PlaceKind::GroupCode => Err(failed(range, "G[n] is written, not read: $P_GG[n] reads the code of group n")),
            PlaceKind::User => {
                if place.indices.is_empty() && !self.store.is_defined(&place.name) && is_axis_name(&place.name) {
                    return Ok(Value::Axis(place.name.clone()));
                }
                let slot = self.slot(place, range)?;
                Ok(self.store.read(slot))
            }
        }
    }

    fn parameter_index(&mut self, place: &Place, range: TextRange) -> Result<usize> {
        let Some(index) = place.indices.first() else { return Err(failed(range, "an R parameter needs its number")) };
        let number = self.value(index)?.int(index.range)?;
        let index = usize::try_from(number).ok().filter(|&n| n < R_PARAMETER_LIMIT).ok_or_else(|| {
            failed(range, format!("there is no R parameter R{number}: R0 to R{}", R_PARAMETER_LIMIT - 1))
        })?;
        if index >= self.store.parameters.len() {
            self.store.parameters.resize(index + 1, 0.0);
        }
        Ok(index)
    }

    /// The variable or element `place` names (a user variable).
    pub fn slot(&mut self, place: &Place, range: TextRange) -> Result<Slot> {
        match place.kind {
            PlaceKind::User => {}
            PlaceKind::Parameter => {
                let index = self.parameter_index(place, range)?;
                return Ok(Slot { cell: Cell::Parameter(index), element: None });
            }
            PlaceKind::System | PlaceKind::GroupCode => {
                return Err(not_modelled(range, format!("{} passed by reference", place.name)));
            }
        }
        let indices: Vec<i64> =
            place.indices.iter().map(|index| self.value(index)?.int(index.range)).collect::<Result<_>>()?;
        let slot = match self.store.lookup(&place.name) {
            Some(slot) => slot,
            None if !indices.is_empty() => self.open_array(&place.name, indices.len(), range),
            None => return Err(failed(range, format!("{} is not defined", place.name))),
        };
        if indices.is_empty() {
            return Ok(slot);
        }
        let dimensions = self.store.variable(slot.cell).map_or(&[][..], |variable| &variable.dimensions[..]);
        if slot.element.is_some() || dimensions.len() != indices.len() {
            let message = format!("{} has {} dimensions, indexed with {}", place.name, dimensions.len(), indices.len());
            return Err(failed(range, message));
        }
        let mut element = 0usize;
        for (&index, &size) in indices.iter().zip(dimensions) {
            let index = usize::try_from(index).ok().filter(|&i| i < size).ok_or_else(|| {
                failed(range, format!("the index {index} of {} is outside 0 to {}", place.name, size - 1))
            })?;
            element = element * size + index;
        }
        Ok(Slot { element: Some(element), ..slot })
    }

    /// A GUD array that nothing defines (see the module documentation).
    fn open_array(&mut self, name: &str, dimensions: usize, range: TextRange) -> Slot {
        self.context.undefined_array(name, range);
        let count = u32::try_from(dimensions).unwrap_or(u32::MAX);
        let size =
            ((OPEN_ARRAY_ELEMENTS as f64).powf(1.0 / f64::from(count)).floor() as usize).clamp(1, OPEN_ARRAY_SIZE);
        let variable =
            Variable { ty: BaseType::Real, length: None, dimensions: vec![size; dimensions], values: Vec::new() };
        let values = vec![Value::Real(0.0); size.pow(count)];
        self.store.globals.push(Variable { values, ..variable });
        self.store.global_names.insert(name.to_owned(), self.store.globals.len() - 1);
        Slot { cell: Cell::Global(self.store.globals.len() - 1), element: None }
    }

    /// `target = value`, with `SET(…)`, `REP(v)` and `(…)` filling an
    /// array from the element `target` names, the last index fastest
    /// (004:4839).
    pub fn assign(&mut self, target: &Place, value: &Expr, range: TextRange) -> Result<()> {
        if let Some(fill) = Fill::of(value) {
            return self.fill(target, fill, range);
        }
        let computed = self.value(value)?;
        self.write(target, computed, range)
    }

    /// Writes `value` to `target`.
    pub fn write(&mut self, target: &Place, value: Value, range: TextRange) -> Result<()> {
        match target.kind {
            PlaceKind::Parameter => {
                let index = self.parameter_index(target, range)?;
                self.store.parameters[index] = value.number(range)?;
                Ok(())
            }
            PlaceKind::System => {
                let indices = self.indices(target)?;
                self.context.write_system(&target.name, &indices, value, range)
            }
            PlaceKind::GroupCode => {
                let Some(group) = target.indices.first() else {
                    return Err(failed(range, "G[n] needs the group's number"));
                };
                let group = self.value(group)?.int(group.range)?;
                let index = value.int(range)?;
                self.context.set_group(group, index, range)
            }
            PlaceKind::User => {
                let slot = self.slot(target, range)?;
                self.store.write(slot, value, range)
            }
        }
    }

    fn fill(&mut self, target: &Place, fill: Fill<'_>, range: TextRange) -> Result<()> {
        let (values, repeat): (Vec<Option<&Expr>>, bool) = match fill {
            Fill::Values(values) => (values.iter().map(Option::as_ref).collect(), false),
            Fill::Repeat(value) => (vec![Some(value)], true),
        };
        let values: Vec<Value> = values
            .into_iter()
            .map(|value| match value {
                Some(expr) => self.value(expr),
                None => Err(failed(range, "SET leaves no value out")),
            })
            .collect::<Result<_>>()?;
        if target.kind == PlaceKind::Parameter {
            let first = self.parameter_index(target, range)?;
            let wanted = if repeat { self.store.parameters.len() - first } else { values.len() };
            if first + wanted > R_PARAMETER_LIMIT {
                return Err(failed(range, "the values go past the last R parameter"));
            }
            if first + wanted > self.store.parameters.len() {
                self.store.parameters.resize(first + wanted, 0.0);
            }
            for offset in 0..wanted {
                self.store.parameters[first + offset] = values[if repeat { 0 } else { offset }].number(range)?;
            }
            return Ok(());
        }
        if target.kind != PlaceKind::User {
            return Err(failed(range, "SET and REP fill arrays"));
        }
        let slot = self.slot(target, range)?;
        let first = slot.element.unwrap_or(0);
        let size = self.store.variable(slot.cell).map_or(1, |variable| variable.values.len());
        let wanted = if repeat { size - first } else { values.len() };
        if first + wanted > size {
            return Err(failed(range, format!("{} values from element {first} go past the array's {size}", wanted)));
        }
        for offset in 0..wanted {
            let value = values[if repeat { 0 } else { offset }].clone();
            self.store.write(Slot { element: Some(first + offset), ..slot }, value, range)?;
        }
        Ok(())
    }

    /// Runs a DEF line's declaration of `declared` in the innermost scope,
    /// or as global user data (a GUD definition file's `DEF NCK`, `DEF
    /// CHAN`).
    pub fn define(&mut self, ty: &Type, declared: &Declared, global: bool) -> Result<()> {
        let range = declared.range;
        let length = match &ty.length {
            Some(expr) => Some(self.size(expr)?),
            None => None,
        };
        let dimensions: Vec<usize> = declared.dimensions.iter().map(|expr| self.size(expr)).collect::<Result<_>>()?;
        if dimensions
            .iter()
            .try_fold(1usize, |total, &size| total.checked_mul(size))
            .is_none_or(|n| n > MAX_ARRAY_ELEMENTS)
        {
            return Err(failed(range, format!("{} has more than {MAX_ARRAY_ELEMENTS} elements", declared.name)));
        }
        if matches!(ty.base, BaseType::Frame | BaseType::Unknown) {
            return Err(not_modelled(range, "FRAME variables"));
        }
        let slot = self.store.declare(&declared.name, ty.base.clone(), length, dimensions, global);
        if let Some(initial) = &declared.initial {
            let place = Place { kind: PlaceKind::User, name: declared.name.clone(), indices: Vec::new() };
            match Fill::of(initial) {
                Some(fill) => self.fill(&place, fill, initial.range)?,
                None => {
                    let value = self.value(initial)?;
                    self.store.write(slot, value, initial.range)?;
                }
            }
        }
        Ok(())
    }

    /// Binds a formal parameter by value in the innermost scope.
    pub fn bind_value(&mut self, name: &str, ty: &Type, value: Option<Value>, range: TextRange) -> Result<()> {
        let length = match &ty.length {
            Some(expr) => Some(self.size(expr)?),
            None => None,
        };
        let base = match ty.base {
            BaseType::Unknown => BaseType::Real,
            ref base => base.clone(),
        };
        let slot = self.store.declare(name, base, length, Vec::new(), false);
        match value {
            Some(value) => self.store.write(slot, value, range),
            None => Ok(()),
        }
    }

    /// An array size or string length.
    fn size(&mut self, expr: &Expr) -> Result<usize> {
        let size = self.value(expr)?.int(expr.range)?;
        usize::try_from(size).ok().filter(|&n| n > 0).ok_or_else(|| failed(expr.range, format!("{size} is no size")))
    }

    fn call(&mut self, name: &str, arguments: &[Option<Expr>], range: TextRange) -> Result<Value> {
        let mut values = Vec::with_capacity(arguments.len());
        for argument in arguments {
            values.push(match argument {
                Some(expr) => Some(self.value(expr)?),
                None => None,
            });
        }
        if name == "ISFILE" {
            let path = argument(&values, 0, range)?.text();
            return Ok(Value::Bool(self.context.is_file(&path)));
        }
        function(name, &values, range)
    }
}

/// A right-hand side that fills an array.
#[derive(Debug)]
enum Fill<'e> {
    Values(&'e [Option<Expr>]),
    Repeat(&'e Expr),
}

impl<'e> Fill<'e> {
    fn of(value: &'e Expr) -> Option<Fill<'e>> {
        match &value.kind {
            ExprKind::Call { name, arguments } if name == "SET" => Some(Fill::Values(arguments)),
            ExprKind::Call { name, arguments } if name == "REP" => {
                arguments.first().and_then(Option::as_ref).map(Fill::Repeat)
            }
            ExprKind::List(values) => Some(Fill::Values(values)),
            _ => None,
        }
    }
}

/// Whether `name` may be an axis (`X`, `A2`, `Z1`): a letter and digits.
fn is_axis_name(name: &str) -> bool {
    let bytes = name.as_bytes();
    !bytes.is_empty()
        && bytes.len() <= 3
        && b"XYZABCUVW".contains(&bytes[0])
        && bytes[1..].iter().all(u8::is_ascii_digit)
}

fn argument(values: &[Option<Value>], index: usize, range: TextRange) -> Result<&Value> {
    values
        .get(index)
        .and_then(Option::as_ref)
        .ok_or_else(|| failed(range, format!("argument {} is missing", index + 1)))
}

fn unary(op: UnaryOp, value: Value, range: TextRange) -> Result<Value> {
    Ok(match op {
        UnaryOp::Plus => match value {
            Value::Int(_) | Value::Real(_) => value,
            other => Value::Real(other.number(range)?),
        },
        UnaryOp::Minus => match value {
            Value::Int(v) => Value::Int(v.checked_neg().ok_or_else(|| failed(range, "an INT overflow"))?),
            other => Value::Real(-other.number(range)?),
        },
        UnaryOp::Not => Value::Bool(!value.truth(range)?),
        UnaryOp::BitNot => Value::Int(!value.int(range)?),
        UnaryOp::ToString => Value::Str(string_value(value.text())),
    })
}

/// Both operands INT, or their numbers.
enum Operands {
    Int(i64, i64),
    Real(f64, f64),
}

fn operands(lhs: &Value, rhs: &Value, range: TextRange) -> Result<Operands> {
    Ok(match (lhs, rhs) {
        (Value::Int(a), Value::Int(b)) => Operands::Int(*a, *b),
        _ => Operands::Real(lhs.number(range)?, rhs.number(range)?),
    })
}

fn binary(op: BinaryOp, lhs: Value, rhs: Value, range: TextRange) -> Result<Value> {
    let overflow = || failed(range, "an INT overflow");
    let by_zero = || failed(range, "a division by zero");
    Ok(match op {
        BinaryOp::Add | BinaryOp::Sub | BinaryOp::Mul => match operands(&lhs, &rhs, range)? {
            Operands::Int(a, b) => Value::Int(
                match op {
                    BinaryOp::Add => a.checked_add(b),
                    BinaryOp::Sub => a.checked_sub(b),
                    _ => a.checked_mul(b),
                }
                .ok_or_else(overflow)?,
            ),
            Operands::Real(a, b) => Value::Real(match op {
                BinaryOp::Add => a + b,
                BinaryOp::Sub => a - b,
                _ => a * b,
            }),
        },
        BinaryOp::Div => {
            let (a, b) = (lhs.number(range)?, rhs.number(range)?);
            if b == 0.0 {
                return Err(by_zero());
            }
            Value::Real(a / b)
        }
        BinaryOp::IntDiv => {
            let (a, b) = (lhs.number(range)?, rhs.number(range)?);
            if b == 0.0 {
                return Err(by_zero());
            }
            Value::Real((a / b).trunc()).int(range).map(Value::Int)?
        }
        BinaryOp::Mod => match operands(&lhs, &rhs, range)? {
            Operands::Int(_, 0) => return Err(by_zero()),
            Operands::Int(a, b) => Value::Int(a.checked_rem(b).ok_or_else(overflow)?),
            Operands::Real(_, 0.0) => return Err(by_zero()),
            Operands::Real(a, b) => Value::Real(a % b),
        },
        BinaryOp::BitAnd => Value::Int(lhs.int(range)? & rhs.int(range)?),
        BinaryOp::BitXor => Value::Int(lhs.int(range)? ^ rhs.int(range)?),
        BinaryOp::BitOr => Value::Int(lhs.int(range)? | rhs.int(range)?),
        BinaryOp::And => Value::Bool(lhs.truth(range)? && rhs.truth(range)?),
        BinaryOp::Xor => Value::Bool(lhs.truth(range)? != rhs.truth(range)?),
        BinaryOp::Or => Value::Bool(lhs.truth(range)? || rhs.truth(range)?),
        BinaryOp::Concat => Value::Str(string_value(lhs.text() + &rhs.text())),
        BinaryOp::Eq | BinaryOp::Ne | BinaryOp::Lt | BinaryOp::Le | BinaryOp::Gt | BinaryOp::Ge => {
            let order = compare(&lhs, &rhs, range)?;
            Value::Bool(match op {
                BinaryOp::Eq => order.is_eq(),
                BinaryOp::Ne => order.is_ne(),
                BinaryOp::Lt => order.is_lt(),
                BinaryOp::Le => order.is_le(),
                BinaryOp::Gt => order.is_gt(),
                _ => order.is_ge(),
            })
        }
        BinaryOp::Chain => return Err(not_modelled(range, "frame chaining with `:`")),
    })
}

/// Whether two values are equal, as `==` compares them.
pub fn equal(lhs: &Value, rhs: &Value, range: TextRange) -> Result<bool> {
    compare(lhs, rhs, range).map(std::cmp::Ordering::is_eq)
}

/// The order of two values: strings and axes by their text, anything
/// else by number, REALs equal within [`REAL_EQUALITY`].
fn compare(lhs: &Value, rhs: &Value, range: TextRange) -> Result<std::cmp::Ordering> {
    use std::cmp::Ordering;
    match (lhs, rhs) {
        (Value::Str(a) | Value::Axis(a), Value::Str(b) | Value::Axis(b)) => Ok(a.cmp(b)),
        (Value::Int(a), Value::Int(b)) => Ok(a.cmp(b)),
        _ => {
            let (a, b) = (lhs.number(range)?, rhs.number(range)?);
            if (a - b).abs() <= REAL_EQUALITY * a.abs().max(b.abs()) {
                Ok(Ordering::Equal)
            } else {
                Ok(a.partial_cmp(&b).unwrap_or(Ordering::Equal))
            }
        }
    }
}

/// A predefined function of the catalogue.
fn function(name: &str, values: &[Option<Value>], range: TextRange) -> Result<Value> {
    let number = |index: usize| argument(values, index, range)?.number(range);
    let text = |index: usize| argument(values, index, range).map(Value::text);
    let real = |value: f64| {
        if value.is_finite() {
            Ok(Value::Real(value))
        } else {
            Err(failed(range, format!("{name} of a value outside its domain")))
        }
    };
    let domain = |ok: bool, value: f64| {
        if ok { real(value) } else { Err(failed(range, format!("{name} of a value outside its domain"))) }
    };
    match name {
        "SIN" => real(number(0)?.to_radians().sin()),
        "COS" => real(number(0)?.to_radians().cos()),
        "TAN" => {
            let angle = number(0)?;
            domain((angle.rem_euclid(180.0) - 90.0).abs() > 1e-9, angle.to_radians().tan())
        }
        "ASIN" => {
            let x = number(0)?;
            domain(x.abs() <= 1.0, x.asin().to_degrees())
        }
        "ACOS" => {
            let x = number(0)?;
            domain(x.abs() <= 1.0, x.acos().to_degrees())
        }
        "ATAN2" => real(number(0)?.atan2(number(1)?).to_degrees()),
        "SQRT" => {
            let x = number(0)?;
            domain(x >= 0.0, x.sqrt())
        }
        "POT" => real(number(0)?.powi(2)),
        "ABS" => match argument(values, 0, range)? {
            Value::Int(value) => value.checked_abs().map(Value::Int).ok_or_else(|| failed(range, "an INT overflow")),
            other => real(other.number(range)?.abs()),
        },
        "TRUNC" => real(number(0)?.trunc()),
        "ROUND" => real(number(0)?.round()),
        // Away from zero: ROUNDUP(-3.2) is -4 (assumption).
        "ROUNDUP" => {
            let x = number(0)?;
            real(if x < 0.0 { x.floor() } else { x.ceil() })
        }
        "LN" => {
            let x = number(0)?;
            domain(x > 0.0, x.ln())
        }
        "EXP" => real(number(0)?.exp()),
        "MINVAL" => real(number(0)?.min(number(1)?)),
        "MAXVAL" => real(number(0)?.max(number(1)?)),
        "BOUND" => {
            let (min, max, value) = (number(0)?, number(1)?, number(2)?);
            domain(min <= max, value.clamp(min.min(max), max.max(min)))
        }
        "STRLEN" => Ok(Value::Int(text(0)?.len() as i64)),
        "TOUPPER" => Ok(Value::Str(text(0)?.to_uppercase())),
        "TOLOWER" => Ok(Value::Str(text(0)?.to_lowercase())),
        "NUMBER" => {
            let text = text(0)?;
            parse_number(&text).map(Value::Real).ok_or_else(|| failed(range, format!("\"{text}\" is not a number")))
        }
        "ISNUMBER" => Ok(Value::Bool(parse_number(&text(0)?).is_some())),
        "AXSTRING" => Ok(Value::Str(text(0)?.to_ascii_uppercase())),
        "AXNAME" => Ok(Value::Axis(text(0)?.trim().to_ascii_uppercase())),
        "INDEX" | "RINDEX" => {
            let (haystack, needle) = (text(0)?, text(1)?);
            let Some(&byte) = needle.as_bytes().first() else { return Err(failed(range, "no character to look for")) };
            let found = if name == "INDEX" {
                haystack.bytes().position(|b| b == byte)
            } else {
                haystack.bytes().rposition(|b| b == byte)
            };
            Ok(Value::Int(found.map_or(-1, |at| at as i64)))
        }
        "SUBSTR" => {
            let source = text(0)?;
            let start = argument(values, 1, range)?.int(range)?;
            let start = usize::try_from(start).unwrap_or(usize::MAX).min(source.len());
            let length = match values.get(2).and_then(Option::as_ref) {
                Some(length) => usize::try_from(length.int(range)?).unwrap_or(0),
                None => source.len() - start,
            };
            let bytes = &source.as_bytes()[start..(start + length).min(source.len())];
            Ok(Value::Str(String::from_utf8_lossy(bytes).into_owned()))
        }
        "SET" | "REP" => Err(failed(range, format!("{name} fills an array: only on the right of an assignment"))),
        "AC" | "IC" => Err(failed(range, format!("{name}(…) gives an address its dimension: only in a word"))),
        _ => match Dialect::Sinumerik.catalogue().function(name) {
            Some(function) if function.returns.is_none() => {
                Err(failed(range, format!("{name} is a procedure, which gives no value")))
            }
            _ => Err(not_modelled(range, format!("the function {name}"))),
        },
    }
}

#[cfg(test)]
mod tests;
