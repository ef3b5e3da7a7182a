use ncc_syntax::TextRange;

use super::*;
use crate::sinumerik::lower::{StatementKind, tests::lower_text};

/// A run's context with one axis position, and the arrays it was told are
/// undefined.
#[derive(Default)]
struct Fixed {
    files: Vec<String>,
    undefined: Vec<String>,
    groups: Vec<(i64, i64)>,
}

impl Context for Fixed {
    fn system(&mut self, name: &str, indices: &[Value], range: TextRange) -> Result<Value> {
        match (name, indices) {
            ("$AA_IM", [Value::Axis(axis)]) if axis == "X" => Ok(Value::Real(12.5)),
            _ => Err(not_modelled(range, name.to_owned())),
        }
    }

    fn write_system(&mut self, name: &str, _: &[Value], _: Value, range: TextRange) -> Result<()> {
        Err(failed(range, format!("{name} is read-only")))
    }

    fn set_group(&mut self, group: i64, index: i64, _: TextRange) -> Result<()> {
        self.groups.push((group, index));
        Ok(())
    }

    fn is_file(&self, path: &str) -> bool {
        self.files.iter().any(|file| file == path)
    }

    fn undefined_array(&mut self, name: &str, _: TextRange) {
        self.undefined.push(name.to_owned());
    }
}

/// Runs the DEFs and assignments of `text`, every block's statements in
/// order.
fn run(text: &str, store: &mut Store, context: &mut Fixed) -> Result<()> {
    let mut eval = Eval { store, context };
    for block in lower_text(text) {
        for statement in &block.statements {
            match &statement.kind {
                StatementKind::Def(def) => {
                    for declared in &def.names {
                        eval.define(&def.ty, declared, def.scope.is_some())?;
                    }
                }
                StatementKind::Assign { target, value } => eval.assign(target, value, statement.range)?,
                other => panic!("not an assignment: {other:?}"),
            }
        }
    }
    Ok(())
}

/// The value `expr` gives, after the DEFs and assignments of `setup`.
fn value_after(setup: &str, expr: &str) -> Result<Value> {
    let (mut store, mut context) = (Store::new(), Fixed::default());
    run(setup, &mut store, &mut context)?;
    let blocks = lower_text(&format!("R0={expr}\n"));
    let StatementKind::Assign { value, .. } = &blocks[0].statements[0].kind else { panic!("{blocks:?}") };
    Eval { store: &mut store, context: &mut context }.value(value)
}

fn value(expr: &str) -> Value {
    value_after("", expr).unwrap_or_else(|error| panic!("{expr}: {error:?}"))
}

fn error(expr: &str) -> EvalError {
    value_after("", expr).expect_err(expr)
}

#[test]
fn operators_bind_in_the_order_of_their_priority() {
    // NOT before the arithmetic; * / DIV MOD before + -.
    assert_eq!(value("2+3*4"), Value::Int(14));
    assert_eq!(value("2*3+4"), Value::Int(10));
    assert_eq!(value("10-4-3"), Value::Int(3), "left to right");
    assert_eq!(value("7 DIV 2 * 2"), Value::Int(6));
    assert_eq!(value("1+7 MOD 4"), Value::Int(4));
    assert_eq!(value("NOT FALSE AND FALSE"), Value::Bool(false));
    // The bitwise operators: B_AND before B_XOR before B_OR, all after +.
    assert_eq!(value("1 B_OR 2 B_AND 3"), Value::Int(3));
    assert_eq!(value("6 B_XOR 3 B_AND 5"), Value::Int(7));
    assert_eq!(value("1+1 B_AND 2"), Value::Int(2));
    // AND before XOR before OR.
    assert_eq!(value("TRUE OR FALSE AND FALSE"), Value::Bool(true));
    assert_eq!(value("TRUE XOR TRUE AND FALSE"), Value::Bool(true));
    assert_eq!(value("TRUE OR TRUE XOR TRUE"), Value::Bool(true));
    // << after the arithmetic, the comparisons last (004:5047).
    let written = value_after("DEF REAL POCATECNI_R=10\n", "\"G0 X0 Y\"<<POCATECNI_R+5<<\"\"");
    assert_eq!(written.unwrap(), Value::Str("G0 X0 Y15".to_owned()));
    assert_eq!(value("\"A\"<<1==\"A1\""), Value::Bool(true));
    assert_eq!(value("1+2==3"), Value::Bool(true));
}

#[test]
fn conversions_follow_the_types() {
    assert_eq!(value("7/2"), Value::Real(3.5));
    assert_eq!(value("6/2"), Value::Real(3.0));
    assert_eq!(value("1.5+1"), Value::Real(2.5));
    assert_eq!(value("\"N\"<<1632.0"), Value::Str("N1632".to_owned()));
    assert_eq!(value("\"X=\"<<-2.5<<\" \"<<0.1"), Value::Str("X=-2.5 0.1".to_owned()));
    assert_eq!(value("\"B\"<<TRUE<<(1==2)"), Value::Str("B10".to_owned()));
    assert_eq!(value("<<3"), Value::Str("3".to_owned()));
    assert_eq!(real_text(-0.0), "0");
    assert_eq!(real_text(1.0 / 3.0), "0.3333333333333333");
    assert_eq!(value("NUMBER(\"-12.5\")"), Value::Real(-12.5));
    assert_eq!(value("ISNUMBER(\"1X\")"), Value::Bool(false));
    assert_eq!(value("STRLEN(\"ABC\")"), Value::Int(3));
    assert_eq!(value("TOUPPER(\"ab\")<<TOLOWER(\"CD\")"), Value::Str("ABcd".to_owned()));
    assert_eq!(value("INDEX(\"ABCB\",\"B\")"), Value::Int(1));
    assert_eq!(value("RINDEX(\"ABCB\",\"B\")"), Value::Int(3));
    assert_eq!(value("SUBSTR(\"ABCDE\",1,3)"), Value::Str("BCD".to_owned()));
    assert_eq!(value("AXSTRING(X)"), Value::Str("X".to_owned()));
    assert_eq!(value("\"Position:\"<<$AA_IM[X]"), Value::Str("Position:12.5".to_owned()));
    // Assignment converts: REAL to INT rounds, a STRING[n] keeps n bytes
    // and ends at a NUL.
    let setup = "DEF INT NUM\nDEF STRING[3] TXT\nDEF BOOL FLAG\nNUM=2.5\nTXT=\"ABCDE\"\nFLAG=R1+2\n";
    assert_eq!(value_after(setup, "NUM").unwrap(), Value::Int(3));
    assert_eq!(value_after(setup, "TXT").unwrap(), Value::Str("ABC".to_owned()));
    assert_eq!(value_after(setup, "FLAG").unwrap(), Value::Bool(true));
    assert_eq!(value_after("DEF INT NUM\nNUM=-2.5\n", "NUM").unwrap(), Value::Int(-3));
    let cut = Value::Str("AB\0CD".to_owned()).convert(&BaseType::String, None, TextRange::default());
    assert_eq!(cut.unwrap(), Value::Str("AB".to_owned()));
}

#[test]
fn functions_compute_in_degrees() {
    let close = |expr: &str, expected: f64| {
        let Value::Real(actual) = value(expr) else { panic!("{expr}") };
        assert!((actual - expected).abs() < 1e-12, "{expr}: {actual}");
    };
    close("SIN(30)", 0.5);
    close("COS(60)", 0.5);
    close("TAN(45)", 1.0);
    close("ASIN(1)", 90.0);
    close("ACOS(0)", 90.0);
    close("ATAN2(1,1)", 45.0);
    close("SQRT(16)+POT(3)", 13.0);
    close("ABS(-2.5)+TRUNC(-1.7)+ROUND(2.5)+ROUNDUP(1.2)", 2.5 - 1.0 + 3.0 + 2.0);
    close("LN(EXP(2))", 2.0);
    close("MINVAL(3,4)+MAXVAL(3,4)+BOUND(0,10,12)", 17.0);
    assert_eq!(value("ABS(-3)"), Value::Int(3));
    assert_eq!(error("SQRT(-1)").kind, ErrorKind::Failed);
    assert_eq!(error("TAN(90)").kind, ErrorKind::Failed);
    assert_eq!(error("1/0").message, "a division by zero");
    assert_eq!(error("5 MOD 0").message, "a division by zero");
    assert_eq!(error("MY_FUNCTION(1)").kind, ErrorKind::NotModelled);
    assert_eq!(error("MSG(\"x\")").kind, ErrorKind::Failed);
    assert_eq!(error("$P_TOOLNO").kind, ErrorKind::NotModelled);
}

#[test]
fn real_equality_is_relative() {
    assert_eq!(value("0.1+0.2==0.3"), Value::Bool(true));
    assert_eq!(value("1000000.1+0.2<>1000000.3"), Value::Bool(false));
    assert_eq!(value("0.3<0.1+0.2"), Value::Bool(false), "equal is not less");
    assert_eq!(value("1.0000001==1"), Value::Bool(false));
    assert_eq!(value("\"ab\"==\"ab\""), Value::Bool(true));
}

#[test]
fn parameters_take_computed_indices_and_stay_in_range() {
    assert_eq!(value_after("R2=3\nR[R2+1]=7\n", "R4*2").unwrap(), Value::Real(14.0));
    assert_eq!(value_after("R99=1\n", "R99").unwrap(), Value::Real(1.0));
    // Machines have more than the standard 100: R999 runs.
    assert_eq!(value_after("R999=4\n", "R999+R998").unwrap(), Value::Real(4.0));
    assert_eq!(value_after("R[500]=SET(1,2)\n", "R501").unwrap(), Value::Real(2.0));
    let outside = value_after("R[65536]=1\n", "R1").expect_err("R65536");
    assert_eq!(outside.message, "there is no R parameter R65536: R0 to R65535");
    assert!(value_after("R[-1]=1\n", "R1").is_err());
}

#[test]
fn arrays_are_row_major_and_set_and_rep_fill_the_last_index_fastest() {
    let setup = "DEF REAL T[3,2]\nT[0,0]=SET(1,2,3,4)\n";
    assert_eq!(value_after(setup, "T[0,1]").unwrap(), Value::Real(2.0));
    assert_eq!(value_after(setup, "T[1,0]").unwrap(), Value::Real(3.0));
    assert_eq!(value_after(setup, "T[1,1]").unwrap(), Value::Real(4.0));
    assert_eq!(value_after(setup, "T[2,0]").unwrap(), Value::Real(0.0));
    let rep = "DEF INT T[2,3]\nT[0,2]=REP(5)\n";
    assert_eq!(value_after(rep, "T[0,1]+T[0,2]+T[1,0]+T[1,2]").unwrap(), Value::Int(15));
    let list = "DEF INT T[3]=(4,5,6)\n";
    assert_eq!(value_after(list, "T[2]").unwrap(), Value::Int(6));
    let past = value_after("DEF REAL T[2]\nT[1]=SET(1,2)\n", "T[0]").expect_err("past the end");
    assert!(past.message.contains("go past"), "{}", past.message);
    let outside = value_after("DEF REAL T[2]\n", "T[2]").expect_err("index 2");
    assert_eq!(outside.message, "the index 2 of T is outside 0 to 1");
    assert!(value_after("DEF REAL T[2]\n", "T[0,0]").is_err(), "two indices of one dimension");
}

#[test]
fn an_undefined_array_is_a_reported_global() {
    let (mut store, mut context) = (Store::new(), Fixed::default());
    run("VAC_POLE[0,0]=SET(0,10,12)\n", &mut store, &mut context).unwrap();
    assert_eq!(context.undefined, ["VAC_POLE"]);
    assert_eq!(value_of(&mut store, &mut context, "VAC_POLE[0,2]"), Value::Real(12.0));
    // A subprogram's scope sees it; its own DEFs go with it.
    store.push_scope(vec![true, false]);
    run("DEF INT LOCAL=1\n", &mut store, &mut context).unwrap();
    assert!(store.is_defined("VAC_POLE") && store.is_defined("LOCAL"));
    assert!(store.passed(1) && !store.passed(2) && !store.passed(3));
    store.pop_scope();
    assert!(store.is_defined("VAC_POLE") && !store.is_defined("LOCAL"));
}

#[test]
fn a_reference_aliases_the_callers_variable_or_element() {
    let (mut store, mut context) = (Store::new(), Fixed::default());
    run("DEF REAL T[2,2]\nDEF INT N\n", &mut store, &mut context).unwrap();
    let element = Place { kind: PlaceKind::User, name: "T".to_owned(), indices: vec![number(1), number(0)] };
    let whole = Place { kind: PlaceKind::User, name: "N".to_owned(), indices: Vec::new() };
    let mut eval = Eval { store: &mut store, context: &mut context };
    let element = eval.slot(&element, TextRange::default()).unwrap();
    let whole = eval.slot(&whole, TextRange::default()).unwrap();
    store.push_scope(Vec::new());
    store.alias("ONE", element);
    store.alias("TWO", whole);
    run("ONE=4\nTWO=ONE+1\n", &mut store, &mut context).unwrap();
    store.pop_scope();
    assert_eq!(value_of(&mut store, &mut context, "T[1,0]+N"), Value::Real(9.0));
    assert_eq!(value_of(&mut store, &mut context, "N"), Value::Int(5));
}

#[test]
fn group_codes_are_written_through_the_context() {
    let (mut store, mut context) = (Store::new(), Fixed::default());
    run("G[1]=2\n", &mut store, &mut context).unwrap();
    assert_eq!(context.groups, [(1, 2)]);
    assert!(value_after("", "G[1]").is_err());
}

fn number(value: u32) -> Expr {
    lower_text(&format!("R0={value}\n"))
        .remove(0)
        .statements
        .into_iter()
        .find_map(|statement| match statement.kind {
            StatementKind::Assign { value, .. } => Some(*value),
            _ => None,
        })
        .expect("a number")
}

fn value_of(store: &mut Store, context: &mut Fixed, expr: &str) -> Value {
    let blocks = lower_text(&format!("R0={expr}\n"));
    let StatementKind::Assign { value, .. } = &blocks[0].statements[0].kind else { panic!() };
    Eval { store, context }.value(value).unwrap()
}
