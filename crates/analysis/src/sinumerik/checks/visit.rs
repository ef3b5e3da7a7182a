//! The expressions and places of a lowered block, for the rules that read
//! every one of them, and what its statements are.

use nc_exec::sinumerik::lower::{
    Call, Callee, Expr, ExprKind, Jump, JumpTarget, Number, Place, Statement, StatementKind, UnaryOp, Word, WordValue,
};
use ncc_catalog::{Dialect, KeywordKind};

/// Every expression written directly in `statement` (not those inside
/// them), synchronous actions' included.
pub(crate) fn statement_exprs<'a>(statement: &'a Statement, f: &mut impl FnMut(&'a Expr)) {
    match &statement.kind {
        StatementKind::Word(word) => word_exprs(word, f),
        StatementKind::Assign { target, value } => {
            target.indices.iter().for_each(&mut *f);
            f(value);
        }
        StatementKind::Command(command) => {
            each(&command.arguments, f);
            command.words.iter().for_each(|word| word_exprs(word, f));
        }
        StatementKind::Call(call) | StatementKind::ModalCall(Some(call)) => call_exprs(call, f),
        StatementKind::Return { arguments } => each(arguments, f),
        StatementKind::Def(def) => {
            def.ty.length.iter().for_each(&mut *f);
            for declared in &def.names {
                declared.dimensions.iter().chain(&declared.initial).for_each(&mut *f);
            }
        }
        StatementKind::If { condition, jump } => {
            f(condition);
            jump.iter().for_each(|jump| jump_exprs(jump, f));
        }
        StatementKind::While(condition) | StatementKind::Until(condition) => f(condition),
        StatementKind::For { variable, start, end } => {
            variable.indices.iter().for_each(&mut *f);
            f(start);
            f(end);
        }
        StatementKind::RepeatSection { count, .. } => count.iter().for_each(|count| f(count)),
        StatementKind::Case { selector, arms } => {
            f(selector);
            for arm in arms {
                arm.value.iter().for_each(&mut *f);
                jump_exprs(&arm.jump, f);
            }
        }
        StatementKind::Jump(jump) => jump_exprs(jump, f),
        StatementKind::SyncAction { id, condition, actions } => {
            id.iter().for_each(|id| f(&id.number));
            condition.iter().for_each(|condition| f(condition));
            actions.iter().for_each(|action| statement_exprs(action, f));
        }
        StatementKind::ModalCall(None)
        | StatementKind::Proc(_)
        | StatementKind::Extern(_)
        | StatementKind::Define { .. }
        | StatementKind::Else
        | StatementKind::EndIf
        | StatementKind::EndWhile
        | StatementKind::EndFor
        | StatementKind::Repeat
        | StatementKind::Loop
        | StatementKind::EndLoop => {}
    }
}

fn each<'a>(exprs: &'a [Option<Expr>], f: &mut impl FnMut(&'a Expr)) {
    exprs.iter().flatten().for_each(f);
}

fn word_exprs<'a>(word: &'a Word, f: &mut impl FnMut(&'a Expr)) {
    if let Some(WordValue::Expr { expr, .. }) = &word.value {
        f(expr);
    }
}

fn call_exprs<'a>(call: &'a Call, f: &mut impl FnMut(&'a Expr)) {
    call.arguments.iter().flatten().for_each(&mut *f);
    if let Some(WordValue::Expr { expr, .. }) = call.repetitions.as_deref() {
        f(expr);
    }
    // A section's start and end are labels of the called program, no values.
    if let Callee::Indirect { program, .. } = &call.callee {
        f(program);
    }
}

fn jump_exprs<'a>(jump: &'a Jump, f: &mut impl FnMut(&'a Expr)) {
    if let Some(JumpTarget::Computed(expr)) = &jump.target {
        f(expr);
    }
}

/// `expr` and every expression inside it, outermost first.
pub(crate) fn each_expr<'a>(expr: &'a Expr, f: &mut impl FnMut(&'a Expr)) {
    f(expr);
    match &expr.kind {
        ExprKind::Name(place) => place.indices.iter().for_each(|index| each_expr(index, f)),
        ExprKind::Call { arguments, .. } | ExprKind::List(arguments) => {
            arguments.iter().flatten().for_each(|argument| each_expr(argument, f));
        }
        ExprKind::Unary(_, operand) => each_expr(operand, f),
        ExprKind::Binary(_, lhs, rhs) => {
            each_expr(lhs, f);
            each_expr(rhs, f);
        }
        ExprKind::Number(_) | ExprKind::String(_) | ExprKind::Bool(_) | ExprKind::Integer(_) | ExprKind::Malformed => {}
    }
}

/// Every expression of `statements`, nested ones included.
pub(crate) fn all_exprs<'a>(statements: &'a [Statement], f: &mut impl FnMut(&'a Expr)) {
    for statement in statements {
        statement_exprs(statement, &mut |expr| each_expr(expr, f));
    }
}

/// The place a statement writes, if any: an assignment's target or a FOR
/// loop's variable, synchronous actions' included.
pub(crate) fn written_places<'a>(statement: &'a Statement, f: &mut impl FnMut(&'a Place, &'a Statement)) {
    match &statement.kind {
        StatementKind::Assign { target, .. } | StatementKind::For { variable: target, .. } => f(target, statement),
        StatementKind::SyncAction { actions, .. } => actions.iter().for_each(|action| written_places(action, f)),
        _ => {}
    }
}

/// Whether a statement is a word of this address.
pub(crate) fn word_is(statement: &Statement, address: &str) -> bool {
    matches!(&statement.kind, StatementKind::Word(word) if word.address == address)
}

/// Whether a command names a kinematic transformation of the catalogue
/// (`TRAORI`, `TRAFOOF`).
pub(crate) fn is_transformation(name: &str) -> bool {
    Dialect::Sinumerik.catalogue().keyword(name).is_some_and(|keyword| keyword.kind == KeywordKind::Transformation)
}

/// The number of a G word written as a whole number (`G505`).
pub(crate) fn g_number(word: &Word) -> Option<u32> {
    let number = word.value.as_ref().and_then(number)?.whole()?;
    u32::try_from(number).ok()
}

/// A word's value when written as a number, signed or not: `X-5`,
/// `B2=-11.03`.
pub(crate) fn signed_value(value: &WordValue) -> Option<f64> {
    if let WordValue::Expr { expr, .. } = value
        && let ExprKind::Unary(op @ (UnaryOp::Minus | UnaryOp::Plus), operand) = &expr.kind
        && let ExprKind::Number(number) = operand.kind
    {
        return Some(if *op == UnaryOp::Minus { -number.value() } else { number.value() });
    }
    number(value).map(|number| number.value())
}

/// A word's value when written as a number: after the address or `=`.
pub(crate) fn number(value: &WordValue) -> Option<Number> {
    match value {
        WordValue::Literal(number) => Some(*number),
        WordValue::Expr { expr, .. } => match expr.kind {
            ExprKind::Number(number) => Some(number),
            _ => None,
        },
    }
}
