//! Control flow in a run: leaving and repeating the control structures
//! the program model matched, and jumps.

use ncc_syntax::TextRange;

use super::{Flow, Interpreter, Unit};
use crate::{
    sinumerik::{
        eval::{EvalError, Value, equal},
        lower::{CaseArm, Expr, ExprKind, Jump, JumpKind, JumpTarget, Place, StatementKind},
        program::{Resolved, StructureKind},
    },
    trace::RunRule,
};

impl Interpreter<'_> {
    /// The end of the structure of `kind` that `block` starts or
    /// continues (ELSE): the block to go on with.
    pub(super) fn structure_exit(&mut self, block: usize, kind: StructureKind, unit: &Unit, range: TextRange) -> Flow {
        let structure =
            unit.model.structures_at(block).find(|s| s.kind == kind && (s.start == block || s.middle == Some(block)));
        match structure {
            // A false IF goes on after its ELSE; ELSE and a false IF
            // without one at the ENDIF.
            Some(s) if kind == StructureKind::If && s.start == block => Flow::Jump(s.middle.map_or(s.end, |m| m + 1)),
            Some(s) if kind == StructureKind::If => Flow::Jump(s.end),
            Some(s) => Flow::Jump(s.end + 1),
            None => self.unmatched(kind, range),
        }
    }

    /// Back to the start of the structure of `kind` that `block` ends,
    /// `past` blocks after it.
    pub(super) fn structure_back(
        &mut self,
        block: usize,
        kind: StructureKind,
        unit: &Unit,
        range: TextRange,
        past: usize,
    ) -> Flow {
        match unit.model.structures_at(block).find(|s| s.kind == kind && s.end == block) {
            Some(s) => Flow::Jump(s.start + past),
            None => self.unmatched(kind, range),
        }
    }

    pub(super) fn unmatched(&mut self, kind: StructureKind, range: TextRange) -> Flow {
        let name = match kind {
            StructureKind::If => "IF … ENDIF",
            StructureKind::While => "WHILE … ENDWHILE",
            StructureKind::For => "FOR … ENDFOR",
            StructureKind::Repeat => "REPEAT … UNTIL",
            StructureKind::Loop => "LOOP … ENDLOOP",
        };
        let message = format!("{name} is not closed or not opened: the control stops");
        self.state.finding(RunRule::CallTargetMissing, range, &message);
        Flow::Stop
    }

    /// Whether a FOR's variable is still at most its end.
    pub(super) fn for_continues(&mut self, variable: &Place, end: &Expr) -> Option<bool> {
        let current = ExprKind::Name(variable.clone());
        let current = Expr { kind: current, range: end.range };
        let result = (|| {
            let mut eval = self.eval();
            Ok::<_, EvalError>(eval.number(&current)? <= eval.number(end)?)
        })();
        self.check(result)
    }

    /// ENDFOR: the variable steps by 1 and the body runs again while it is
    /// at most the end.
    pub(super) fn end_for(&mut self, block: usize, unit: &Unit, range: TextRange) -> Flow {
        let Some(structure) = unit.model.structures_at(block).find(|s| s.kind == StructureKind::For && s.end == block)
        else {
            return self.unmatched(StructureKind::For, range);
        };
        let header = unit.block(structure.start).statements.iter().find_map(|statement| match &statement.kind {
            StatementKind::For { variable, end, .. } => Some((variable, end)),
            _ => None,
        });
        let Some((variable, end)) = header else { return self.unmatched(StructureKind::For, range) };
        let current = Expr { kind: ExprKind::Name(variable.clone()), range };
        let result = (|| {
            let mut eval = self.eval();
            let next = eval.value(&current)?.number(range)? + 1.0;
            eval.write(variable, Value::Real(next), range)
        })();
        match self.check(result).and_then(|()| self.for_continues(variable, end)) {
            None => Flow::Stop,
            Some(true) => Flow::Jump(structure.start + 1),
            Some(false) => Flow::Next,
        }
    }

    /// CASE: the first arm whose value equals the selector's, else
    /// DEFAULT, else the next block.
    pub(super) fn case(&mut self, block: usize, selector: &Expr, arms: &[CaseArm], unit: &Unit) -> Flow {
        let result = self.eval().value(selector);
        let Some(value) = self.check(result) else { return Flow::Stop };
        for arm in arms {
            let matched = match &arm.value {
                None => true,
                Some(expr) => {
                    let result = self.eval().value(expr).and_then(|arm_value| equal(&value, &arm_value, expr.range));
                    match self.check(result) {
                        Some(matched) => matched,
                        None => return Flow::Stop,
                    }
                }
            };
            if matched {
                return self.jump(block, &arm.jump, unit);
            }
        }
        Flow::Next
    }

    /// Where a jump from `block` leads.
    pub(super) fn jump(&mut self, block: usize, jump: &Jump, unit: &Unit) -> Flow {
        let mut computed_name = None;
        let resolved = match &jump.target {
            Some(JumpTarget::Computed(expr)) => {
                let result = self.eval().value(expr);
                let Some(name) = self.check(result) else { return Flow::Stop };
                let name = name.text().trim().to_ascii_uppercase();
                let number = name.strip_prefix('N').or_else(|| name.strip_prefix(':'));
                let target =
                    match number.filter(|digits| !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())) {
                        Some(digits) => JumpTarget::BlockNumber(digits.parse().ok()),
                        None => JumpTarget::Label(name.clone()),
                    };
                let computed = Jump { kind: jump.kind, target: Some(target), range: jump.range };
                computed_name = Some(name);
                unit.model.resolve(block, &computed)
            }
            _ => unit.model.resolve(block, jump),
        };
        match resolved {
            Resolved::Block(target) => Flow::Jump(target),
            Resolved::Start => Flow::Jump(0),
            Resolved::NotFound { alarm: false } => Flow::Next,
            Resolved::NotFound { alarm: true } | Resolved::Computed | Resolved::NoTarget => {
                let direction = match jump.kind {
                    JumpKind::GotoF => " after it",
                    JumpKind::GotoB => " before it",
                    _ => "",
                };
                let target = computed_name.map_or_else(String::new, |name| format!(" {name}"));
                let message = format!("the jump's target{target} is not in the program{direction}: the control stops");
                self.state.finding(RunRule::CallTargetMissing, jump.range, &message);
                Flow::Stop
            }
        }
    }
}
