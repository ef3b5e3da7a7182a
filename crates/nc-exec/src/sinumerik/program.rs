//! The program model of one Sinumerik file over its lowered blocks: labels
//! and block numbers, the control structures matched across blocks, the
//! PROC header, EXTERN and DEF declarations, every jump with the block it
//! reaches, and the calls of programs.
//!
//! Jumps search as the Siemens manual says (digest §2.5, Siemens
//! documentation, not in the thesis, which only uses the suffixes that
//! way): GOTOF forward, GOTOB backward, GOTO forward and then backward, and
//! GOTOC like GOTO but with no alarm when the target is missing. Forward
//! means the blocks after the jump's; backward the jump's block and those
//! before it, so `LOOP1: … GOTOB LOOP1` on one line repeats the line
//! (assumption). Duplicate labels and block numbers are kept for a rule;
//! a jump takes the nearest in its direction.
//!
//! Control structures pair as a stack: an end closes the innermost open
//! structure of its kind, and the structures opened inside it and still
//! open are listed as not closed. The nesting depth is kept for the limit
//! of 16 levels (004:1464).

use std::collections::BTreeMap;

use smallvec::SmallVec;

use super::lower::{Callee, Declared, Extern, Jump, JumpKind, JumpTarget, Proc, SinumerikBlock, StatementKind, Type};

/// The most program levels, the main program included (004:1464): the
/// run's limit and the checker's.
pub const PROGRAM_LEVELS: usize = 16;

/// The blocks carrying a label or number: almost always one, kept without
/// an allocation of its own.
pub type Blocks = SmallVec<[usize; 1]>;

/// The blocks carrying each block number, as sorted pairs: a CAM program
/// numbers every block, and a map's insert per block took most of the
/// time of the model.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BlockNumbers {
    /// Sorted by number, then block.
    numbers: Vec<u64>,
    blocks: Vec<usize>,
}

impl BlockNumbers {
    /// The blocks carrying `number`, in file order.
    pub fn get(&self, number: u64) -> &[usize] {
        let start = self.numbers.partition_point(|&n| n < number);
        let end = start + self.numbers[start..].partition_point(|&n| n == number);
        &self.blocks[start..end]
    }

    /// Each number with its blocks, in ascending order.
    pub fn iter(&self) -> impl Iterator<Item = (u64, &[usize])> {
        let starts = (0..self.numbers.len()).filter(|&i| i == 0 || self.numbers[i - 1] != self.numbers[i]);
        starts.map(|start| (self.numbers[start], self.get(self.numbers[start])))
    }

    /// Every numbered block, by number.
    pub fn blocks(&self) -> &[usize] {
        &self.blocks
    }

    /// From pairs of a number and its block, in file order.
    fn new(mut numbered: Vec<(u64, usize)>) -> BlockNumbers {
        // Programs mostly number in ascending order: a sort that finds
        // runs takes one pass over them.
        numbered.sort();
        numbered.into_iter().unzip::<_, _, Vec<_>, Vec<_>>().into()
    }
}

impl From<(Vec<u64>, Vec<usize>)> for BlockNumbers {
    fn from((numbers, blocks): (Vec<u64>, Vec<usize>)) -> BlockNumbers {
        BlockNumbers { numbers, blocks }
    }
}

/// The model of one file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SinumerikModel {
    /// Every block carrying each label (upper case), in file order.
    pub labels: BTreeMap<String, Blocks>,
    /// Every block carrying each block number (`N10` or `:10`), in file
    /// order.
    pub block_numbers: BlockNumbers,
    /// The matched structures, in the order they close.
    pub structures: Vec<Structure>,
    /// Starts never closed, ends and ELSEs without their start, in the
    /// order found.
    pub unmatched: Vec<Unmatched>,
    /// Every PROC line; the program's own is the first (004:1415-1421).
    pub procs: Vec<Declaration<Proc>>,
    pub externs: Vec<Declaration<Extern>>,
    /// Each name a DEF declares, in order.
    pub definitions: Vec<Definition>,
    pub jumps: Vec<JumpSite>,
    /// The calls of programs and cycles (not of predefined procedures).
    pub calls: Vec<CallSite>,
    /// Each block where a structure starts, continues or ends, with the
    /// structure's index, sorted: a run looks them up at every loop pass.
    at_block: Vec<(usize, usize)>,
}

/// A declaration with its block.
#[derive(Debug, Clone, PartialEq)]
pub struct Declaration<T> {
    pub block: usize,
    pub declaration: T,
}

/// A name declared by DEF.
#[derive(Debug, Clone, PartialEq)]
pub struct Definition {
    pub block: usize,
    /// `NCK` or `CHAN`.
    pub scope: Option<String>,
    pub ty: Type,
    pub declared: Declared,
}

/// A control structure matched across blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Structure {
    pub kind: StructureKind,
    pub start: usize,
    /// The ELSE block of an IF.
    pub middle: Option<usize>,
    pub end: usize,
    /// 1 for an outermost structure.
    pub depth: usize,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StructureKind {
    /// `IF` … [`ELSE` …] `ENDIF`.
    If,
    /// `WHILE` … `ENDWHILE`.
    While,
    /// `FOR` … `ENDFOR`.
    For,
    /// `REPEAT` … `UNTIL`.
    Repeat,
    /// `LOOP` … `ENDLOOP`.
    Loop,
}

/// A part of a control structure without its partner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unmatched {
    pub block: usize,
    pub kind: StructureKind,
    pub problem: Unbalanced,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unbalanced {
    /// A start without its end.
    NotClosed,
    /// An end without its start.
    NotOpened,
    /// An ELSE outside an IF, or a second ELSE.
    StrayElse,
}

/// A jump and where it leads.
#[derive(Debug, Clone, PartialEq)]
pub struct JumpSite {
    pub block: usize,
    pub jump: Jump,
    pub resolved: Resolved,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Resolved {
    Block(usize),
    /// `GOTOS`: the program's start.
    Start,
    /// A string expression: only a run knows the target.
    Computed,
    /// No block in the searched direction has the target; `alarm` is
    /// false for GOTOC, which then goes on with the next block.
    NotFound {
        alarm: bool,
    },
    /// The target is missing or malformed; the parser reported it.
    NoTarget,
}

/// A call of a program or cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct CallSite {
    pub block: usize,
    pub callee: Callee,
    /// Positions written, omitted ones included: `PROFIL(,TRUE)` has 2.
    pub arguments: usize,
    /// `MCALL`: after every block with a path motion.
    pub modal: bool,
}

/// Whether the model reads more of `block` than its number: a label, or a
/// statement it models.
pub fn marked(block: &SinumerikBlock) -> bool {
    block.label.is_some() || block.modelled
}

/// The number `block` carries (`N10` or `:10`).
pub fn block_number(block: &SinumerikBlock) -> Option<u64> {
    block.number.and_then(|number| number.value)
}

impl SinumerikModel {
    /// The model of the blocks in file order; they are read twice, so a
    /// file kept in pieces needs no copy.
    pub fn new<'a, I>(blocks: I) -> SinumerikModel
    where
        I: IntoIterator<Item = &'a SinumerikBlock>,
        I::IntoIter: Clone,
    {
        let blocks = blocks.into_iter().enumerate();
        let numbered = blocks.clone().filter_map(|(index, block)| Some((block_number(block)?, index)));
        SinumerikModel::from_marks(numbered, blocks.filter(|(_, block)| marked(block)))
    }

    /// The model of a file from its numbered blocks and its [`marked`]
    /// ones, each with its index and in file order: the other blocks say
    /// nothing to it. A file kept in chunks lists them per chunk, and an
    /// edit reads the blocks of the chunk it touched only.
    pub fn from_marks<'a>(
        numbered: impl IntoIterator<Item = (u64, usize)>,
        marked: impl IntoIterator<Item = (usize, &'a SinumerikBlock)>,
    ) -> SinumerikModel {
        let mut model = SinumerikModel::default();
        let mut open = Opened::default();
        // One pass, the jumps resolved after it, once every label is known.
        for (index, block) in marked {
            if let Some(label) = &block.label {
                model.labels.entry(label.name.clone()).or_default().push(index);
            }
            for statement in block.statements.iter().filter(|_| block.modelled) {
                model.structure(&mut open, index, &statement.kind);
                model.declarations_and_calls(index, &statement.kind);
            }
        }
        model.block_numbers = BlockNumbers::new(numbered.into_iter().collect());
        let mut jumps = std::mem::take(&mut model.jumps);
        for site in &mut jumps {
            site.resolved = model.resolve(site.block, &site.jump);
        }
        model.jumps = jumps;
        model.unmatched.extend(open.structures.into_iter().map(|o| Unmatched {
            block: o.start,
            kind: o.kind,
            problem: Unbalanced::NotClosed,
        }));
        for (index, s) in model.structures.iter().enumerate() {
            model.at_block.push((s.start, index));
            // A one-line `IF … GOTO … ENDIF` starts and ends in its block.
            let others = s.middle.into_iter().chain([s.end]).filter(|&block| block != s.start);
            model.at_block.extend(others.map(|block| (block, index)));
        }
        model.at_block.sort_unstable();
        model
    }

    /// The PROC header of the program.
    pub fn header(&self) -> Option<&Declaration<Proc>> {
        self.procs.first()
    }

    /// The structures that start, continue or end at `block`.
    pub fn structures_at(&self, block: usize) -> impl Iterator<Item = &Structure> {
        let first = self.at_block.partition_point(|&(at, _)| at < block);
        let here = self.at_block[first..].iter().take_while(move |&&(at, _)| at == block);
        here.map(|&(_, index)| &self.structures[index])
    }

    /// The jumps written in `block`.
    pub fn jumps_from(&self, block: usize) -> impl Iterator<Item = &JumpSite> {
        // Found in block order.
        let first = self.jumps.partition_point(|site| site.block < block);
        self.jumps[first..].iter().take_while(move |site| site.block == block)
    }

    /// The block a jump from `from` reaches (see the module documentation).
    pub fn resolve(&self, from: usize, jump: &Jump) -> Resolved {
        let candidates = match &jump.target {
            _ if jump.kind == JumpKind::GotoS => return Resolved::Start,
            None | Some(JumpTarget::BlockNumber(None)) => return Resolved::NoTarget,
            Some(JumpTarget::Computed(_)) => return Resolved::Computed,
            Some(JumpTarget::Label(label)) => self.labels.get(label).map(|blocks| blocks.as_slice()),
            Some(JumpTarget::BlockNumber(Some(number))) => Some(self.block_numbers.get(*number)),
        };
        let candidates = candidates.unwrap_or_default();
        let forward = || candidates.iter().copied().find(|&block| block > from);
        let backward = || candidates.iter().copied().rev().find(|&block| block <= from);
        let found = match jump.kind {
            JumpKind::GotoF => forward(),
            JumpKind::GotoB => backward(),
            JumpKind::Goto | JumpKind::GotoC | JumpKind::GotoS => forward().or_else(backward),
        };
        found.map_or(Resolved::NotFound { alarm: jump.kind != JumpKind::GotoC }, Resolved::Block)
    }

    fn structure(&mut self, state: &mut Opened, block: usize, statement: &StatementKind) {
        // Controls' own cycles close a one-line conditional jump with an
        // ENDIF: the next structure statement after it, if an ENDIF that no
        // open IF takes, pairs with it (the control runs the pair as the
        // jump alone). An open IF takes the ENDIF, as cycles also write.
        match statement {
            StatementKind::If { jump: Some(_), .. } => {
                state.jump_if = Some(block);
                return;
            }
            StatementKind::EndIf
                if let Some(start) = state.jump_if.take()
                    && !state.structures.iter().any(|open| open.kind == StructureKind::If) =>
            {
                let depth = state.structures.len() + 1;
                self.structures.push(Structure { kind: StructureKind::If, start, middle: None, end: block, depth });
                return;
            }
            kind if kind.is_structure() => state.jump_if = None,
            _ => return,
        }
        let open = &mut state.structures;
        let start = |kind| Some(Open { kind, start: block, middle: None });
        let opened = match statement {
            StatementKind::If { jump: None, .. } => start(StructureKind::If),
            StatementKind::While(_) => start(StructureKind::While),
            StatementKind::For { .. } => start(StructureKind::For),
            StatementKind::Repeat => start(StructureKind::Repeat),
            StatementKind::Loop => start(StructureKind::Loop),
            _ => None,
        };
        if let Some(opened) = opened {
            open.push(opened);
            return;
        }
        let closes = match statement {
            StatementKind::Else => {
                match open.last_mut() {
                    Some(top) if top.kind == StructureKind::If && top.middle.is_none() => top.middle = Some(block),
                    _ => self.unmatched.push(Unmatched {
                        block,
                        kind: StructureKind::If,
                        problem: Unbalanced::StrayElse,
                    }),
                }
                return;
            }
            StatementKind::EndIf => StructureKind::If,
            StatementKind::EndWhile => StructureKind::While,
            StatementKind::EndFor => StructureKind::For,
            StatementKind::Until(_) => StructureKind::Repeat,
            StatementKind::EndLoop => StructureKind::Loop,
            _ => return,
        };
        let Some(at) = open.iter().rposition(|o| o.kind == closes) else {
            self.unmatched.push(Unmatched { block, kind: closes, problem: Unbalanced::NotOpened });
            return;
        };
        for inner in open.drain(at + 1..) {
            self.unmatched.push(Unmatched { block: inner.start, kind: inner.kind, problem: Unbalanced::NotClosed });
        }
        if let Some(opened) = open.pop() {
            let depth = open.len() + 1;
            self.structures.push(Structure {
                kind: opened.kind,
                start: opened.start,
                middle: opened.middle,
                end: block,
                depth,
            });
        }
    }

    fn declarations_and_calls(&mut self, block: usize, statement: &StatementKind) {
        match statement {
            StatementKind::Proc(proc) => self.procs.push(Declaration { block, declaration: proc.clone() }),
            StatementKind::Extern(declaration) => {
                self.externs.push(Declaration { block, declaration: declaration.clone() });
            }
            StatementKind::Def(def) => {
                self.definitions.extend(def.names.iter().map(|declared| Definition {
                    block,
                    scope: def.scope.clone(),
                    ty: def.ty.clone(),
                    declared: declared.clone(),
                }));
            }
            StatementKind::Jump(jump) | StatementKind::If { jump: Some(jump), .. } => self.jump(block, jump),
            StatementKind::Case { arms, .. } => arms.iter().for_each(|arm| self.jump(block, &arm.jump)),
            StatementKind::Call(call) | StatementKind::ModalCall(Some(call))
                if !matches!(call.callee, Callee::Predefined(_)) =>
            {
                let modal = matches!(statement, StatementKind::ModalCall(_));
                let arguments = call.arguments.len();
                self.calls.push(CallSite { block, callee: call.callee.clone(), arguments, modal });
            }
            _ => {}
        }
    }

    /// Notes the jump; it is resolved once the labels are known.
    fn jump(&mut self, block: usize, jump: &Jump) {
        self.jumps.push(JumpSite { block, jump: jump.clone(), resolved: Resolved::NoTarget });
    }
}

/// A structure still open while the blocks are read.
struct Open {
    kind: StructureKind,
    start: usize,
    middle: Option<usize>,
}

/// The structures open while the model is built, and a one-line
/// conditional jump with no structure statement after it yet.
#[derive(Default)]
struct Opened {
    structures: Vec<Open>,
    jump_if: Option<usize>,
}

#[cfg(test)]
mod tests;
