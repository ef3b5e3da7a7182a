//! Rules on the types of values (digest §6 rules 45, 46, 63, 64, 66 and
//! the type mismatches), over a static inference: a variable has the type
//! its DEF or PROC line gives, an R parameter is REAL, a system variable
//! and a predefined function have the catalogue's type, a literal its
//! own; what none of them tells is unknown and never reported.
//!
//! Assumptions (Siemens documentation, not in the seed): INT, REAL, BOOL
//! and CHAR convert into each other, CHAR and STRING into each other, and
//! nothing else into STRING, AXIS or FRAME; arithmetic takes numbers, so
//! a STRING or BOOL in `+ - * /` is a mismatch. Rule 66 leaves out a
//! comparison with a whole number written as such (`R6==2`), the usual
//! switch test, whose exactness no one doubts.

use std::{cell::RefCell, collections::HashMap};

use nc_exec::sinumerik::{
    lower::{
        BaseType, BinaryOp, Callee, Expr, ExprKind, Parameter, Place, PlaceKind, Proc, Statement, StatementKind, Type,
        UnaryOp,
    },
    program::Declaration,
};
use ncc_catalog::{Catalogue, Dialect, SystemVariableInfo};
use ncc_syntax::TextRange;

use crate::lowered::Watched;
use crate::{
    Diagnostic,
    db::Db,
    diagnostic::declare_rules,
    sinumerik::{checks::visit::statement_exprs, model::FileModel},
};

declare_rules! {
    OMITTED_REFERENCE_ARGUMENT = "K045", "omitted-reference-argument", Error, "A call that leaves out the argument of a VAR (by reference) or AXIS parameter.";
    CALL_DOES_NOT_FIT = "K046", "call-does-not-fit", Error, "A call with more arguments than the program's parameters, a value for a VAR parameter, or an argument of a type the parameter cannot take.";
    REAL_LITERAL_TO_INT = "K063", "real-literal-to-int", Info, "A number with a fraction or decimal point assigned to an INT variable, which rounds it.";
    STRING_TOO_LONG = "K064", "string-too-long", Error, "A string literal longer than the STRING[n] variable it is assigned to.";
    REAL_EQUALITY = "K066", "real-equality", Hint, "`==` or `<>` on REAL values, which the control compares with a relative tolerance (not against a whole number written as such, `R6==2`).";
    TYPE_MISMATCH = "K106", "type-mismatch", Error, "A value of a type its place cannot take: a STRING in arithmetic or assigned to a number, a number assigned to a STRING.";
}

/// The type of a value, as far as the program says it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ty {
    Int,
    Real,
    Bool,
    Char,
    Str,
    Axis,
    Frame,
    Unknown,
}

impl Ty {
    fn of(base: &BaseType) -> Ty {
        match base {
            BaseType::Int => Ty::Int,
            BaseType::Real => Ty::Real,
            BaseType::Bool => Ty::Bool,
            BaseType::Char => Ty::Char,
            BaseType::String => Ty::Str,
            BaseType::Axis => Ty::Axis,
            BaseType::Frame => Ty::Frame,
            BaseType::Unknown => Ty::Unknown,
        }
    }

    /// A catalogue type: `REAL`, `VAR INT`, `STRING[255] array`, `AXIS…`.
    fn named(text: &str) -> Ty {
        let text = text.strip_prefix("VAR ").unwrap_or(text);
        match text.split(|c: char| !c.is_ascii_alphabetic()).next().unwrap_or_default() {
            "INT" => Ty::Int,
            "REAL" => Ty::Real,
            "BOOL" => Ty::Bool,
            "CHAR" => Ty::Char,
            "STRING" => Ty::Str,
            "AXIS" => Ty::Axis,
            "FRAME" => Ty::Frame,
            _ => Ty::Unknown,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Ty::Int => "INT",
            Ty::Real => "REAL",
            Ty::Bool => "BOOL",
            Ty::Char => "CHAR",
            Ty::Str => "STRING",
            Ty::Axis => "AXIS",
            Ty::Frame => "FRAME",
            Ty::Unknown => "unknown",
        }
    }

    fn numeric(self) -> bool {
        matches!(self, Ty::Int | Ty::Real | Ty::Bool | Ty::Char)
    }

    fn textual(self) -> bool {
        matches!(self, Ty::Char | Ty::Str)
    }

    /// Whether a value of type `self` cannot go where `to` is expected.
    fn cannot_become(self, to: Ty) -> bool {
        match (self, to) {
            (Ty::Unknown, _) | (_, Ty::Unknown) => false,
            (from, to) if from == to => false,
            (from, to) if from.numeric() && to.numeric() => false,
            (from, to) if from.textual() && to.textual() => false,
            _ => true,
        }
    }
}

/// The workspace's PROC lines by program name, with the file they are in.
pub(crate) type Signatures<'a> = HashMap<&'a str, (&'a str, &'a FileModel, &'a Declaration<Proc>)>;

/// The name a call gives a program, as its PROC line writes it:
/// `_N_NAME_SPF` is NAME.
pub(crate) fn program_name(name: &str) -> &str {
    name.strip_prefix("_N_").and_then(|n| n.strip_suffix("_SPF").or_else(|| n.strip_suffix("_MPF"))).unwrap_or(name)
}

pub(crate) fn check(db: &dyn Db, file: &FileModel, signatures: &Signatures<'_>) -> Vec<Diagnostic> {
    let catalogue = Dialect::Sinumerik.catalogue();
    let mut variables: HashMap<&str, &Type> = HashMap::new();
    for proc in &file.model.procs {
        for parameter in &proc.declaration.parameters {
            if let Some(name) = &parameter.name {
                variables.insert(name, &parameter.ty);
            }
        }
    }
    for definition in &file.model.definitions {
        variables.insert(&definition.declared.name, &definition.ty);
    }
    let types = Types { catalogue, variables, known: RefCell::default() };
    let mut out = Vec::new();
    for (index, block) in file.blocks(db).enumerate() {
        let offset = file.ranges[index].start();
        for statement in &block.statements {
            let mut found = Vec::new();
            let signature = types.statement(file, statement, signatures, &mut found);
            statement_exprs(statement, &mut |expr| {
                types.infer(expr, &mut found);
            });
            for diagnostic in found {
                let diagnostic = diagnostic.shifted(offset);
                let call = [OMITTED_REFERENCE_ARGUMENT.code, CALL_DOES_NOT_FIT.code].contains(&diagnostic.code);
                out.push(match &signature {
                    Some((path, at, label)) if call => diagnostic.with_related(path.clone(), *at, label.clone()),
                    _ => diagnostic,
                });
            }
        }
    }
    out
}

/// Where the parameters a call is checked against are declared: the file
/// (`None`: this one), the place, and what it is.
type Signature = (Option<String>, TextRange, String);

struct Types<'a> {
    catalogue: &'a Catalogue,
    variables: HashMap<&'a str, &'a Type>,
    /// The types of the system variables and functions used, looked up
    /// once each: the catalogue's lists are searched.
    known: RefCell<HashMap<String, Ty>>,
}

/// Whether `expr` is a whole number written without a point.
fn whole_literal(expr: &Expr) -> bool {
    matches!(&expr.kind, ExprKind::Number(n) if !n.decimal.has_point() && n.exponent == 0)
        || matches!(expr.kind, ExprKind::Integer(_))
        || matches!(&expr.kind, ExprKind::Unary(UnaryOp::Minus, inner) if whole_literal(inner))
}

impl Types<'_> {
    /// The type of a place.
    fn place(&self, place: &Place) -> Ty {
        match place.kind {
            PlaceKind::Parameter => Ty::Real,
            PlaceKind::GroupCode => Ty::Int,
            PlaceKind::User => self.variables.get(place.name.as_str()).map_or(Ty::Unknown, |ty| Ty::of(&ty.base)),
            PlaceKind::System => self.known(&place.name, |catalogue, name| match catalogue.system_variable(name) {
                Some(SystemVariableInfo::Documented(variable)) => Ty::named(&variable.ty),
                _ => Ty::Unknown,
            }),
        }
    }

    /// The type the catalogue gives `name`, by `look_up` the first time.
    fn known(&self, name: &str, look_up: impl FnOnce(&Catalogue, &str) -> Ty) -> Ty {
        if let Some(&ty) = self.known.borrow().get(name) {
            return ty;
        }
        let ty = look_up(self.catalogue, name);
        self.known.borrow_mut().insert(name.to_owned(), ty);
        ty
    }

    /// The length of a STRING[n] variable.
    fn length(&self, place: &Place) -> Option<usize> {
        if place.kind != PlaceKind::User {
            return None;
        }
        let ty = self.variables.get(place.name.as_str())?;
        match &ty.length.as_ref()?.kind {
            ExprKind::Number(n) if ty.base == BaseType::String => n.whole().and_then(|n| usize::try_from(n).ok()),
            _ => None,
        }
    }

    /// The type of `expr`, reporting the mismatches inside it.
    fn infer(&self, expr: &Expr, out: &mut Vec<Diagnostic>) -> Ty {
        match &expr.kind {
            ExprKind::Number(_) => Ty::Real,
            ExprKind::Integer(_) => Ty::Int,
            ExprKind::String(_) => Ty::Str,
            ExprKind::Bool(_) => Ty::Bool,
            ExprKind::Name(place) => {
                for index in &place.indices {
                    self.infer(index, out);
                }
                self.place(place)
            }
            ExprKind::Call { name, arguments } => {
                for argument in arguments.iter().flatten() {
                    self.infer(argument, out);
                }
                self.known(name, |catalogue, name| {
                    catalogue.function(name).and_then(|f| f.returns.as_deref()).map_or(Ty::Unknown, Ty::named)
                })
            }
            ExprKind::List(values) => {
                for value in values.iter().flatten() {
                    self.infer(value, out);
                }
                Ty::Unknown
            }
            ExprKind::Unary(op, operand) => {
                let ty = self.infer(operand, out);
                match op {
                    UnaryOp::Plus | UnaryOp::Minus => {
                        self.arithmetic(operand, ty, out);
                        ty
                    }
                    UnaryOp::Not => Ty::Bool,
                    UnaryOp::BitNot => Ty::Int,
                    UnaryOp::ToString => Ty::Str,
                }
            }
            ExprKind::Binary(op, lhs, rhs) => {
                let (left, right) = (self.infer(lhs, out), self.infer(rhs, out));
                self.binary(*op, (lhs, left), (rhs, right), out)
            }
            ExprKind::Malformed => Ty::Unknown,
        }
    }

    fn binary(
        &self,
        op: BinaryOp,
        (lhs, left): (&Expr, Ty),
        (rhs, right): (&Expr, Ty),
        out: &mut Vec<Diagnostic>,
    ) -> Ty {
        match op {
            BinaryOp::Add | BinaryOp::Sub | BinaryOp::Mul | BinaryOp::Div | BinaryOp::IntDiv | BinaryOp::Mod => {
                let left_ok = self.arithmetic(lhs, left, out);
                let right_ok = self.arithmetic(rhs, right, out);
                match op {
                    BinaryOp::IntDiv | BinaryOp::Mod => Ty::Int,
                    _ if left == Ty::Int && right == Ty::Int && op != BinaryOp::Div => Ty::Int,
                    _ if left_ok && right_ok => Ty::Real,
                    _ => Ty::Unknown,
                }
            }
            BinaryOp::BitAnd | BinaryOp::BitOr | BinaryOp::BitXor => Ty::Int,
            BinaryOp::And | BinaryOp::Or | BinaryOp::Xor => {
                for (operand, ty) in [(lhs, left), (rhs, right)] {
                    if ty.cannot_become(Ty::Bool) {
                        let message = format!("a {} is no truth value: {} takes BOOL values", ty.name(), operator(op));
                        out.push(Diagnostic::new(&TYPE_MISMATCH, operand.range, message));
                    }
                }
                Ty::Bool
            }
            BinaryOp::Concat => Ty::Str,
            BinaryOp::Chain => Ty::Frame,
            BinaryOp::Eq | BinaryOp::Ne | BinaryOp::Lt | BinaryOp::Le | BinaryOp::Gt | BinaryOp::Ge => {
                if left.cannot_become(right) && right.cannot_become(left) {
                    let message =
                        format!("a {} is compared with a {}: they cannot be compared", left.name(), right.name());
                    out.push(Diagnostic::new(
                        &TYPE_MISMATCH,
                        TextRange::new(lhs.range.start(), rhs.range.end()),
                        message,
                    ));
                } else if matches!(op, BinaryOp::Eq | BinaryOp::Ne)
                    && (left == Ty::Real || right == Ty::Real)
                    && [left, right].iter().all(|ty| matches!(ty, Ty::Int | Ty::Real))
                    && !whole_literal(lhs)
                    && !whole_literal(rhs)
                {
                    let message = "REAL values compare equal within a relative tolerance on Sinumerik, not exactly: a difference test (`ABS(A-B)<1E-6`) says what is meant";
                    out.push(Diagnostic::new(
                        &REAL_EQUALITY,
                        TextRange::new(lhs.range.start(), rhs.range.end()),
                        message,
                    ));
                }
                Ty::Bool
            }
        }
    }

    /// Reports an operand of arithmetic that is no number; whether it is one.
    fn arithmetic(&self, operand: &Expr, ty: Ty, out: &mut Vec<Diagnostic>) -> bool {
        if matches!(ty, Ty::Int | Ty::Real | Ty::Unknown) {
            return true;
        }
        let message = format!("a {} in arithmetic, which takes numbers", ty.name());
        out.push(Diagnostic::new(&TYPE_MISMATCH, operand.range, message));
        false
    }

    /// The checks of what a statement assigns or passes; for a call, where
    /// the parameters it is checked against are declared.
    fn statement(
        &self,
        file: &FileModel,
        statement: &Statement,
        signatures: &Signatures<'_>,
        out: &mut Vec<Diagnostic>,
    ) -> Option<Signature> {
        match &statement.kind {
            StatementKind::Assign { target, value } => {
                self.assign(self.place(target), self.length(target), &target.name, value, out);
            }
            StatementKind::Def(def) => {
                for declared in &def.names {
                    let Some(initial) = &declared.initial else { continue };
                    let length = match def.ty.length.as_ref().map(|l| &l.kind) {
                        Some(ExprKind::Number(n)) => n.whole().and_then(|n| usize::try_from(n).ok()),
                        _ => None,
                    };
                    self.assign(Ty::of(&def.ty.base), length, &declared.name, initial, out);
                }
            }
            StatementKind::If { condition, .. } | StatementKind::While(condition) | StatementKind::Until(condition) => {
                let ty = self.infer(condition, &mut Vec::new());
                if ty.cannot_become(Ty::Bool) {
                    let message = format!("the condition is a {}, no truth value", ty.name());
                    out.push(Diagnostic::new(&TYPE_MISMATCH, condition.range, message));
                }
            }
            StatementKind::Call(call) | StatementKind::ModalCall(Some(call)) => {
                let Callee::Program(name) = &call.callee else { return None };
                let name = program_name(name);
                if let Some(&(path, other, proc)) = signatures.get(name) {
                    self.call(name, &call.arguments, &proc.declaration.parameters, statement.range, out);
                    let at = other.in_file(proc.block, TextRange::default());
                    return Some((Some(path.to_owned()), at, format!("PROC {name}")));
                }
                let declared = file.model.externs.iter().find(|e| e.declaration.name == name)?;
                self.call(name, &call.arguments, &declared.declaration.parameters, statement.range, out);
                return Some((None, file.in_file(declared.block, TextRange::default()), format!("EXTERN {name}")));
            }
            _ => {}
        }
        None
    }

    /// An assignment of `value` to a place of type `to` (of `length`
    /// characters, for a STRING).
    fn assign(&self, to: Ty, length: Option<usize>, name: &str, value: &Expr, out: &mut Vec<Diagnostic>) {
        let ty = self.infer(value, &mut Vec::new());
        if ty.cannot_become(to) {
            let message = format!("a {} cannot be assigned to {name}, a {}", ty.name(), to.name());
            out.push(Diagnostic::new(&TYPE_MISMATCH, value.range, message));
            return;
        }
        match &value.kind {
            ExprKind::Number(number) if to == Ty::Int && (number.decimal.has_point() || number.whole().is_none()) => {
                let message = format!("{name} is an INT: {} is rounded to a whole number", number.decimal);
                out.push(Diagnostic::new(&REAL_LITERAL_TO_INT, value.range, message));
            }
            ExprKind::String(text) if length.is_some_and(|length| text.chars().count() > length) => {
                let message = format!(
                    "the string has {} characters and {name} holds {}",
                    text.chars().count(),
                    length.unwrap_or_default()
                );
                out.push(Diagnostic::new(&STRING_TOO_LONG, value.range, message));
            }
            _ => {}
        }
    }

    /// Rules 45 and 46: a call's arguments against the parameters.
    fn call(
        &self,
        name: &str,
        arguments: &[Option<Expr>],
        parameters: &[Parameter],
        range: TextRange,
        out: &mut Vec<Diagnostic>,
    ) {
        if arguments.len() > parameters.len() {
            let message = format!("{name} takes {} arguments, and {} are given", parameters.len(), arguments.len());
            out.push(Diagnostic::new(&CALL_DOES_NOT_FIT, range, message));
        }
        for (position, parameter) in parameters.iter().enumerate() {
            let what = parameter.name.as_deref().map_or_else(|| format!("argument {}", position + 1), |n| n.to_owned());
            match arguments.get(position).and_then(Option::as_ref) {
                None if parameter.by_reference || parameter.ty.base == BaseType::Axis => {
                    let kind = if parameter.by_reference { "a VAR parameter" } else { "an AXIS parameter" };
                    let message = format!("{name} is called without {what}, {kind}, which must be given");
                    out.push(Diagnostic::new(&OMITTED_REFERENCE_ARGUMENT, range, message));
                }
                None => {}
                Some(argument) => {
                    if parameter.by_reference && !matches!(argument.kind, ExprKind::Name(_)) {
                        let message = format!("{what} of {name} is a VAR parameter: it takes a variable, not a value");
                        out.push(Diagnostic::new(&CALL_DOES_NOT_FIT, argument.range, message));
                        continue;
                    }
                    let ty = self.infer(argument, &mut Vec::new());
                    let to = Ty::of(&parameter.ty.base);
                    if ty.cannot_become(to) {
                        let message = format!("{what} of {name} is a {}: a {} cannot be passed", to.name(), ty.name());
                        out.push(Diagnostic::new(&CALL_DOES_NOT_FIT, argument.range, message));
                    }
                }
            }
        }
    }
}

fn operator(op: BinaryOp) -> &'static str {
    match op {
        BinaryOp::And => "AND",
        BinaryOp::Or => "OR",
        _ => "XOR",
    }
}
