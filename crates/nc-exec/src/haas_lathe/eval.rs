//! Macro expressions evaluated over the macro variables, with values that
//! may be unknown, so the executor (everything known) and the checker
//! (partly unknown) share one evaluator.
//!
//! The lathe manual describes no macro variables or expressions (it names
//! only G65, lathe manual §6.21 (001:135)); the operators follow the
//! catalogue's operations, which come from Haas documentation. Where that is
//! silent the Fanuc custom-macro conventions are assumed, each marked
//! below:
//!
//! - A variable never set is *vacant* (Fanuc "null"), and `#0` always is.
//!   In arithmetic and functions a vacant operand counts as 0; `EQ`/`NE`
//!   tell vacant from 0, the other comparisons take it as 0; a vacant value
//!   alone or negated stays vacant (assumption from Fanuc; not in the
//!   manual).
//! - Comparisons give 1 or 0; a condition is true when its value is
//!   non-zero, and a vacant condition is false (assumption from Fanuc).
//! - `MOD`, `AND`, `OR`, `XOR` take the integer parts (catalogue); `MOD`
//!   keeps the sign of the dividend (assumption from Fanuc).
//! - `ROUND` rounds half away from zero, `FIX` toward zero, `FUP` away from
//!   zero (`FUP[-1.2]` is −2) (assumption from Fanuc).
//! - `ATAN[v]` lies in −90°…90° (catalogue); `ATAN[y]/[x]` in 0°…360°, and
//!   `ASIN` in −90°…90°, `ACOS` in 0°…180° (assumption from Fanuc).
//! - A variable number with a fraction is rounded to the nearest whole
//!   number (assumption from Fanuc).

use std::sync::Arc;

use super::lower::{BinaryOp, Expr, ExprKind, Function, UnaryOp};
use crate::known::Known;
use ncc_syntax::TextRange;

/// A macro variable's value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MacroValue {
    /// Never set (Fanuc "null").
    Vacant,
    Number(f64),
}

impl MacroValue {
    /// The value in arithmetic, where vacant counts as 0.
    fn number(self) -> f64 {
        match self {
            MacroValue::Vacant => 0.0,
            MacroValue::Number(value) => value,
        }
    }
}

/// Why an expression has no value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EvalError {
    DivisionByZero {
        range: TextRange,
    },
    /// An argument outside the function's domain: `SQRT[-1]`, `ASIN[2]`,
    /// `TAN[90]`.
    OutOfDomain {
        function: Function,
        range: TextRange,
    },
    /// A variable number the control does not have.
    NoSuchVariable {
        number: i64,
        range: TextRange,
    },
    /// `#[#1]` with `#1` vacant.
    VacantVariableNumber {
        range: TextRange,
    },
    /// Assigning to `#0`, which stays vacant.
    ReadOnlyVariable {
        number: u32,
        range: TextRange,
    },
    /// What the parser already reported as malformed.
    Malformed {
        range: TextRange,
    },
}

/// The macro variables: `#1`–`#33` locals, `#100`–`#199` and `#500`–`#699`
/// commons (catalogue, from Haas documentation); system variables from
/// `#1000` on read as unknown, as nothing here models them.
#[derive(Debug, Clone, PartialEq)]
pub struct Variables {
    /// The locals, then `#100`–`#199`, then `#500`–`#699`. Shared until
    /// written: the checker's walk keeps a copy before and after each
    /// block, and few blocks write a variable.
    values: Arc<[Known<MacroValue>; 333]>,
}

/// How many locals there are: `#1`–`#33`.
const LOCALS: usize = 33;

/// The local variables `#1`–`#33` of one macro call level.
#[derive(Debug, Clone, PartialEq)]
pub struct Locals([Known<MacroValue>; LOCALS]);

impl Locals {
    /// Every local vacant, as a macro call level starts (assumption from
    /// Fanuc).
    pub fn vacant() -> Locals {
        Locals([Known::Is(MacroValue::Vacant); LOCALS])
    }

    /// Sets `#number`, a number from 1 to 33; others are not locals and
    /// change nothing.
    pub fn set(&mut self, number: u32, value: Known<MacroValue>) {
        if let Some(local) = usize::try_from(number).ok().and_then(|n| n.checked_sub(1)).and_then(|i| self.0.get_mut(i))
        {
            *local = value;
        }
    }
}

/// Where `#number` is kept in [`Variables::values`].
fn slot(number: u32) -> Option<usize> {
    let number = usize::try_from(number).ok()?;
    match number {
        1..=33 => Some(number - 1),
        100..=199 => Some(number - 100 + 33),
        500..=699 => Some(number - 500 + 133),
        _ => None,
    }
}

impl Variables {
    /// The variables at power-on: locals and `#100`–`#199` vacant;
    /// `#500`–`#699` unknown, as the control keeps them over power-off
    /// (assumption from Haas documentation; not in the manual).
    pub fn at_power_on() -> Variables {
        let mut values = [Known::Is(MacroValue::Vacant); 333];
        values[133..].fill(Known::Unknown);
        Variables { values: Arc::new(values) }
    }

    /// The locals `#1`–`#33`, which a macro call (G65) keeps per level.
    pub fn locals(&self) -> Locals {
        let mut locals = Locals::vacant();
        locals.0.copy_from_slice(&self.values[..LOCALS]);
        locals
    }

    /// Puts `locals` in place of `#1`–`#33`.
    pub fn set_locals(&mut self, locals: &Locals) {
        Arc::make_mut(&mut self.values)[..LOCALS].copy_from_slice(&locals.0);
    }

    /// Every variable unknown, for reading a program with no assumption
    /// about how it is called.
    pub fn unknown() -> Variables {
        Variables { values: Arc::new([Known::Unknown; 333]) }
    }

    /// The value of `#number`; `None` when the control has no such
    /// variable.
    pub fn get(&self, number: u32) -> Option<Known<MacroValue>> {
        match number {
            0 => Some(Known::Is(MacroValue::Vacant)),
            1000.. => Some(Known::Unknown),
            _ => slot(number).map(|slot| self.values[slot]),
        }
    }

    /// Stores `value` in `#number`; `false` when the number is not a
    /// writable macro variable (system variables are not modelled).
    pub fn set(&mut self, number: u32, value: Known<MacroValue>) -> bool {
        match slot(number) {
            Some(slot) => {
                Arc::make_mut(&mut self.values)[slot] = value;
                true
            }
            None => false,
        }
    }

    /// Evaluates `expr`.
    pub fn eval(&self, expr: &Expr) -> Result<Known<MacroValue>, EvalError> {
        let range = expr.range;
        match &expr.kind {
            ExprKind::Literal(decimal) => Ok(Known::Is(MacroValue::Number(decimal.to_f64()))),
            ExprKind::Variable(index) => match self.variable_number(index)? {
                Known::Is(number) => u32::try_from(number)
                    .ok()
                    .and_then(|n| self.get(n))
                    .ok_or(EvalError::NoSuchVariable { number, range }),
                Known::Unknown => Ok(Known::Unknown),
            },
            ExprKind::Unary(op, operand) => Ok(match (op, self.eval(operand)?) {
                (UnaryOp::Minus, Known::Is(MacroValue::Number(v))) => Known::Is(MacroValue::Number(-v)),
                (_, value) => value,
            }),
            ExprKind::Binary(op, lhs, rhs) => binary(*op, self.eval(lhs)?, self.eval(rhs)?, range),
            ExprKind::Call(function, arguments) => {
                let mut values = Vec::with_capacity(arguments.len());
                for argument in arguments {
                    values.push(self.eval(argument)?);
                }
                call(*function, &values, range)
            }
            ExprKind::Malformed => Err(EvalError::Malformed { range }),
        }
    }

    /// The number of the variable `#[index]` names.
    pub fn variable_number(&self, index: &Expr) -> Result<Known<i64>, EvalError> {
        match self.eval(index)? {
            Known::Is(MacroValue::Number(value)) => Ok(Known::Is(value.round() as i64)),
            Known::Is(MacroValue::Vacant) => Err(EvalError::VacantVariableNumber { range: index.range }),
            Known::Unknown => Ok(Known::Unknown),
        }
    }

    /// Evaluates a condition of `IF` or `WHILE`.
    pub fn condition(&self, expr: &Expr) -> Result<Known<bool>, EvalError> {
        Ok(match self.eval(expr)? {
            Known::Is(MacroValue::Number(value)) => Known::Is(value != 0.0),
            Known::Is(MacroValue::Vacant) => Known::Is(false),
            Known::Unknown => Known::Unknown,
        })
    }

    /// Runs `#target = value`. Writes to system variables (`#1000` on)
    /// are accepted and not kept. With an unknown target number nothing
    /// known remains of the variables it may have written.
    pub fn assign(&mut self, target: &Expr, value: &Expr) -> Result<(), EvalError> {
        let value = self.eval(value)?;
        let range = target.range;
        match self.variable_number(target)? {
            Known::Is(0) => Err(EvalError::ReadOnlyVariable { number: 0, range }),
            Known::Is(number) => match u32::try_from(number) {
                Ok(n) if n >= 1000 => Ok(()),
                Ok(n) if self.set(n, value) => Ok(()),
                _ => Err(EvalError::NoSuchVariable { number, range }),
            },
            Known::Unknown => {
                *self = Variables::unknown();
                Ok(())
            }
        }
    }
}

fn truth(value: bool) -> MacroValue {
    MacroValue::Number(if value { 1.0 } else { 0.0 })
}

fn binary(
    op: BinaryOp,
    lhs: Known<MacroValue>,
    rhs: Known<MacroValue>,
    range: TextRange,
) -> Result<Known<MacroValue>, EvalError> {
    // A known zero divisor is an error whatever the dividend.
    if matches!(op, BinaryOp::Div | BinaryOp::Mod) {
        let zero = match (op, rhs) {
            (BinaryOp::Div, Known::Is(r)) => r.number() == 0.0,
            (BinaryOp::Mod, Known::Is(r)) => r.number().trunc() == 0.0,
            _ => false,
        };
        if zero {
            return Err(EvalError::DivisionByZero { range });
        }
    }
    let (Known::Is(lhs), Known::Is(rhs)) = (lhs, rhs) else {
        return Ok(Known::Unknown);
    };
    let (l, r) = (lhs.number(), rhs.number());
    let int = |v: f64| v.trunc() as i64;
    let value = match op {
        BinaryOp::Add => MacroValue::Number(l + r),
        BinaryOp::Sub => MacroValue::Number(l - r),
        BinaryOp::Mul => MacroValue::Number(l * r),
        BinaryOp::Div => MacroValue::Number(l / r),
        BinaryOp::Mod => MacroValue::Number(int(l).wrapping_rem(int(r)) as f64),
        BinaryOp::And => MacroValue::Number((int(l) & int(r)) as f64),
        BinaryOp::Or => MacroValue::Number((int(l) | int(r)) as f64),
        BinaryOp::Xor => MacroValue::Number((int(l) ^ int(r)) as f64),
        BinaryOp::Eq => truth(lhs == rhs),
        BinaryOp::Ne => truth(lhs != rhs),
        BinaryOp::Gt => truth(l > r),
        BinaryOp::Ge => truth(l >= r),
        BinaryOp::Lt => truth(l < r),
        BinaryOp::Le => truth(l <= r),
    };
    Ok(Known::Is(value))
}

fn call(function: Function, arguments: &[Known<MacroValue>], range: TextRange) -> Result<Known<MacroValue>, EvalError> {
    let numbers: Option<Vec<f64>> = arguments.iter().map(|a| a.known().map(MacroValue::number)).collect();
    let out_of_domain = EvalError::OutOfDomain { function, range };
    let value = match (function, arguments.len()) {
        (Function::Atan, 1 | 2) | (_, 1) => {
            let Some(numbers) = numbers else { return Ok(Known::Unknown) };
            let v = numbers[0];
            match function {
                Function::Sin => v.to_radians().sin(),
                Function::Cos => v.to_radians().cos(),
                Function::Tan if (v.rem_euclid(180.0) - 90.0).abs() < 1e-9 => return Err(out_of_domain),
                Function::Tan => v.to_radians().tan(),
                Function::Atan => match numbers.get(1) {
                    Some(&x) => v.atan2(x).to_degrees().rem_euclid(360.0),
                    None => v.atan().to_degrees(),
                },
                Function::Asin | Function::Acos if !(-1.0..=1.0).contains(&v) => return Err(out_of_domain),
                Function::Asin => v.asin().to_degrees(),
                Function::Acos => v.acos().to_degrees(),
                Function::Sqrt if v < 0.0 => return Err(out_of_domain),
                Function::Sqrt => v.sqrt(),
                Function::Abs => v.abs(),
                Function::Round => v.round(),
                Function::Fix => v.trunc(),
                Function::Fup => {
                    if v < 0.0 {
                        v.floor()
                    } else {
                        v.ceil()
                    }
                }
            }
        }
        _ => return Err(EvalError::Malformed { range }),
    };
    Ok(Known::Is(MacroValue::Number(value)))
}

#[cfg(test)]
mod tests {
    use ncc_syntax::{Dialect, Parse};

    use super::*;
    use crate::haas_lathe::lower::{HaasBlock, Statement};

    /// The value of `#1 = <text>` over `variables`.
    fn eval_with(variables: &Variables, text: &str) -> Result<Known<MacroValue>, EvalError> {
        let parse = Parse::new(&format!("#1 = {text}\n"), Dialect::HaasLathe);
        let tree = parse.green();
        let run = tree.children().next().and_then(|c| c.into_node()).expect("a block run");
        let block = run.children().next().and_then(|c| c.into_node()).expect("a block");
        match &HaasBlock::lower(block).statements[..] {
            [Statement::Assign { value, .. }] => variables.eval(value),
            other => panic!("not one assignment: {other:?}"),
        }
    }

    fn value(text: &str) -> f64 {
        match eval_with(&Variables::at_power_on(), text) {
            Ok(Known::Is(MacroValue::Number(v))) => v,
            other => panic!("{text}: {other:?}"),
        }
    }

    #[test]
    fn arithmetic_follows_the_fanuc_precedence() {
        assert_eq!(value("2 + 3 * 4"), 14.0);
        assert_eq!(value("[2 + 3] * 4"), 20.0);
        assert_eq!(value("7 / 2"), 3.5);
        assert_eq!(value("-[3] - -2"), -1.0);
        assert_eq!(value("27 MOD 20"), 7.0);
        assert_eq!(value("-7 MOD 3"), -1.0);
        assert_eq!(value("5 AND 3"), 1.0);
        assert_eq!(value("1 OR 2"), 3.0);
        assert_eq!(value("5 XOR 3"), 6.0);
    }

    #[test]
    fn functions_work_in_degrees_and_round_as_fanuc() {
        let close = |text: &str, expected: f64| assert!((value(text) - expected).abs() < 1e-12, "{text}");
        close("SIN[30.]", 0.5);
        close("COS[60.]", 0.5);
        close("TAN[45.]", 1.0);
        close("ATAN[1.]", 45.0);
        close("ATAN[-1.]/[-1.]", 225.0);
        close("ASIN[0.5]", 30.0);
        close("ACOS[0.5]", 60.0);
        close("SQRT[9.]", 3.0);
        close("ABS[-15.]", 15.0);
        assert_eq!(value("ROUND[1.714]"), 2.0);
        assert_eq!(value("ROUND[-2.5]"), -3.0);
        assert_eq!(value("FIX[3.54]"), 3.0);
        assert_eq!(value("FIX[-3.54]"), -3.0);
        assert_eq!(value("FUP[3.2]"), 4.0);
        assert_eq!(value("FUP[-1.2]"), -2.0);
    }

    #[test]
    fn comparisons_give_one_or_zero_and_tell_vacant_from_zero() {
        assert_eq!(value("[1 LT 2] + [2 LE 2] + [3 GT 4] + [3 GE 4]"), 2.0);
        assert_eq!(value("#0 EQ 0"), 0.0);
        assert_eq!(value("#0 EQ #5"), 1.0);
        assert_eq!(value("#0 NE 0"), 1.0);
        assert_eq!(value("#0 LT 1"), 1.0);
        assert_eq!(value("#0 + 2"), 2.0);
        let vacant = eval_with(&Variables::at_power_on(), "-#7");
        assert_eq!(vacant, Ok(Known::Is(MacroValue::Vacant)));
    }

    #[test]
    fn errors_are_reported_with_their_expression() {
        let error = |text: &str| eval_with(&Variables::at_power_on(), text).expect_err(text);
        assert!(matches!(error("1 / 0"), EvalError::DivisionByZero { .. }));
        assert!(matches!(error("1 MOD 0.5"), EvalError::DivisionByZero { .. }));
        assert!(matches!(error("SQRT[-1.]"), EvalError::OutOfDomain { function: Function::Sqrt, .. }));
        assert!(matches!(error("ASIN[2.]"), EvalError::OutOfDomain { .. }));
        assert!(matches!(error("TAN[-90.]"), EvalError::OutOfDomain { .. }));
        assert!(matches!(error("#40"), EvalError::NoSuchVariable { number: 40, .. }));
        assert!(matches!(error("#[#3]"), EvalError::VacantVariableNumber { .. }));
        assert!(matches!(error("[1 +"), EvalError::Malformed { .. }));
    }

    #[test]
    fn unknown_values_spread_but_a_known_zero_divisor_is_still_an_error() {
        let unknown = Variables::unknown();
        assert_eq!(eval_with(&unknown, "#5 * 2 + SIN[#6]"), Ok(Known::Unknown));
        assert_eq!(eval_with(&unknown, "#[#5]"), Ok(Known::Unknown));
        assert!(matches!(eval_with(&unknown, "#5 / 0"), Err(EvalError::DivisionByZero { .. })));
        assert_eq!(eval_with(&Variables::at_power_on(), "#600 + #1000"), Ok(Known::Unknown));
    }

    #[test]
    fn assignments_write_the_variable_the_index_names() {
        let mut variables = Variables::at_power_on();
        let parse = Parse::new("#2 = 4\n#[#2 + 100] = -#2 * 2.\n#0 = 1\n", Dialect::HaasLathe);
        let tree = parse.green();
        let run = tree.children().next().and_then(|c| c.into_node()).expect("a block run");
        let mut results = Vec::new();
        for block in run.children().filter_map(|c| c.into_node()) {
            for statement in HaasBlock::lower(block).statements {
                if let Statement::Assign { target, value, .. } = statement {
                    results.push(variables.assign(&target, &value));
                }
            }
        }
        assert!(results[..2].iter().all(Result::is_ok));
        assert!(matches!(results[2], Err(EvalError::ReadOnlyVariable { number: 0, .. })));
        assert_eq!(variables.get(104), Some(Known::Is(MacroValue::Number(-8.0))));
        assert_eq!(variables.get(40), None);
    }

    #[test]
    fn every_catalogue_operation_is_evaluated() {
        for operation in &Dialect::HaasLathe.catalogue().operations {
            let symbol = operation.symbol.as_deref().expect("expression operators have a symbol");
            let known = BinaryOp::from_symbol(symbol).is_some() || Function::from_name(symbol).is_some();
            assert!(known, "operation `{symbol}` has no evaluation");
        }
    }
}
