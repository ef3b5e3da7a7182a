//! The printed form of lowered blocks (`ncc lower`): the statements of a
//! block separated by `|`, every operation of an expression in
//! parentheses, places with their indices, `_` for an omitted argument.

use std::fmt;

use super::*;

impl fmt::Display for SinumerikBlock {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&show_block(self))
    }
}

fn show(expr: &Expr) -> String {
    match &expr.kind {
        ExprKind::Number(number) => show_number(number),
        ExprKind::String(text) => format!("{text:?}"),
        ExprKind::Bool(value) => value.to_string(),
        ExprKind::Integer(value) => format!("int {value}"),
        ExprKind::Name(place) => show_place(place),
        ExprKind::Call { name, arguments } => format!("{name}({})", show_list(arguments)),
        ExprKind::Unary(op, operand) => format!("({op:?} {})", show(operand)),
        ExprKind::Binary(op, lhs, rhs) => format!("({} {op:?} {})", show(lhs), show(rhs)),
        ExprKind::List(values) => format!("list({})", show_list(values)),
        ExprKind::Malformed => "?".to_owned(),
    }
}

fn show_number(number: &Number) -> String {
    match number.exponent {
        0 => number.decimal.to_string(),
        exponent => format!("{}EX{exponent}", number.decimal),
    }
}

fn show_list(values: &[Option<Expr>]) -> String {
    values.iter().map(|value| value.as_ref().map_or("_".to_owned(), show)).collect::<Vec<_>>().join(", ")
}

fn show_place(place: &Place) -> String {
    let indices: Vec<String> = place.indices.iter().map(show).collect();
    let kind = match place.kind {
        PlaceKind::Parameter | PlaceKind::User => "",
        PlaceKind::System => "sys:",
        PlaceKind::GroupCode => "group:",
    };
    if indices.is_empty() {
        format!("{kind}{}", place.name)
    } else {
        format!("{kind}{}[{}]", place.name, indices.join(", "))
    }
}

fn show_value(value: Option<&WordValue>) -> String {
    match value {
        None => "?".to_owned(),
        Some(WordValue::Literal(number)) => show_number(number),
        Some(WordValue::Expr { expr, dimension: None }) => format!("={}", show(expr)),
        Some(WordValue::Expr { expr, dimension: Some(dimension) }) => format!("={dimension:?}({})", show(expr)),
    }
}

fn show_word(word: &Word) -> String {
    format!("{}{}", word.address, show_value(word.value.as_ref()))
}

fn show_type(ty: &Type) -> String {
    match &ty.length {
        Some(length) => format!("{:?}[{}]", ty.base, show(length)),
        None => format!("{:?}", ty.base),
    }
}

fn show_parameters(parameters: &[Parameter]) -> String {
    let shown: Vec<String> = parameters
        .iter()
        .map(|p| {
            let dimensions: Vec<String> = p.dimensions.iter().map(show).collect();
            format!(
                "{}{} {}{}",
                if p.by_reference { "var " } else { "" },
                show_type(&p.ty),
                p.name.as_deref().unwrap_or("-"),
                if dimensions.is_empty() { String::new() } else { format!("[{}]", dimensions.join(", ")) }
            )
        })
        .collect();
    shown.join(", ")
}

fn show_jump(jump: &Jump) -> String {
    let target = match &jump.target {
        None => "-".to_owned(),
        Some(JumpTarget::BlockNumber(number)) => format!("N{}", number.map_or("?".to_owned(), |n| n.to_string())),
        Some(JumpTarget::Label(label)) => format!("label {label}"),
        Some(JumpTarget::Computed(expr)) => format!("computed {}", show(expr)),
    };
    format!("{:?} {target}", jump.kind)
}

fn show_call(call: &Call) -> String {
    let callee = match &call.callee {
        Callee::Indirect { program, section } => {
            let section = section.as_deref().map_or(String::new(), |(start, end)| {
                format!(" block {} to {}", show(start), end.as_ref().map_or("-".to_owned(), show))
            });
            format!("Indirect {}{section}", show(program))
        }
        callee => format!("{callee:?}"),
    };
    let repetitions = call.repetitions.as_deref().map_or(String::new(), |r| format!(" P{}", show_value(Some(r))));
    format!("call {callee}({}){repetitions}", show_list(&call.arguments))
}

fn show_statement(statement: &Statement) -> String {
    match &statement.kind {
        StatementKind::Word(word) => show_word(word),
        StatementKind::Assign { target, value } => format!("{} := {}", show_place(target), show(value)),
        StatementKind::Command(command) => {
            let words: Vec<String> = command.words.iter().map(show_word).collect();
            format!("cmd {}({}) [{}]", command.name, show_list(&command.arguments), words.join(" "))
        }
        StatementKind::Call(call) => show_call(call),
        StatementKind::ModalCall(call) => format!("mcall {}", call.as_ref().map_or("off".to_owned(), show_call)),
        StatementKind::Return { arguments } => format!("ret({})", show_list(arguments)),
        StatementKind::Def(def) => {
            let names: Vec<String> = def
                .names
                .iter()
                .map(|d| {
                    let dimensions: Vec<String> = d.dimensions.iter().map(show).collect();
                    let initial = d.initial.as_ref().map_or(String::new(), |i| format!(" = {}", show(i)));
                    format!("{}[{}]{initial}", d.name, dimensions.join(", "))
                })
                .collect();
            format!("def {:?} {} {}", def.scope, show_type(&def.ty), names.join("; "))
        }
        StatementKind::Proc(proc) => {
            format!("proc {}({}) {:?}", proc.name, show_parameters(&proc.parameters), proc.attributes)
        }
        StatementKind::Extern(declaration) => {
            format!("extern {}({})", declaration.name, show_parameters(&declaration.parameters))
        }
        StatementKind::Define { name, text } => format!("define {name} as {text:?}"),
        StatementKind::If { condition, jump } => {
            format!("if {}{}", show(condition), jump.as_ref().map_or(String::new(), |j| format!(" {}", show_jump(j))))
        }
        StatementKind::While(condition) => format!("while {}", show(condition)),
        StatementKind::Until(condition) => format!("until {}", show(condition)),
        StatementKind::For { variable, start, end } => {
            format!("for {} = {} to {}", show_place(variable), show(start), show(end))
        }
        StatementKind::RepeatSection { start, end, count } => {
            format!("repeat {start}..{end:?} times {}", count.as_deref().map_or("-".to_owned(), show))
        }
        StatementKind::Case { selector, arms } => {
            let arms: Vec<String> = arms
                .iter()
                .map(|arm| {
                    format!("{} => {}", arm.value.as_ref().map_or("default".to_owned(), show), show_jump(&arm.jump))
                })
                .collect();
            format!("case {} of {}", show(selector), arms.join("; "))
        }
        StatementKind::Jump(jump) => show_jump(jump),
        StatementKind::SyncAction { id, condition, actions } => {
            let id = id.as_ref().map_or(String::new(), |id| format!("{}={} ", id.keyword, show(&id.number)));
            let actions: Vec<String> = actions.iter().map(show_statement).collect();
            format!("sync {id}{} do {}", condition.as_deref().map_or("-".to_owned(), show), actions.join(" "))
        }
        other => format!("{other:?}"),
    }
}

fn show_block(block: &SinumerikBlock) -> String {
    let mut items = Vec::new();
    if let Some(skip) = block.skip {
        items.push(format!("/{:?}", skip.level));
    }
    if let Some(header) = &block.header {
        items.push(format!("%{}", header.name));
    }
    if let Some(number) = block.number {
        let value = number.value.map_or("?".to_owned(), |value| value.to_string());
        items.push(format!("{}{value}", if number.main { ":" } else { "N" }));
    }
    if let Some(label) = &block.label {
        items.push(format!("{}:", label.name));
    }
    items.extend(block.statements.iter().map(show_statement));
    items.join(" | ")
}
