//! Looking entries up by what a programmer types: `G40`, `M30`, `R39`,
//! `op:48`, `X`, `group:G3`; Sinumerik's `BSPLINE`, `GOTOF`, `SIN`, `<<`,
//! `$P_GG[6]`, `CYCLE832`.

use crate::{
    Address, AddressRole, Catalogue, Code, Cycle, Function, Group, Keyword, MachineConstant, Operation,
    ParameterStatus, SystemVariable, SystemVariableInfo, VariablePrefix,
};

/// One thing the catalogue can describe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Item<'a> {
    Group(&'a Group),
    Code(&'a Code),
    /// An M code the catalogue does not list, which belongs to an open group
    /// (the machine builder defines it).
    UnlistedCode {
        letter: char,
        number: u32,
        group: &'a Group,
    },
    Address(&'a Address),
    /// Program parameter `R<number>`.
    Parameter(u32),
    /// Machine constant `number` (the entry may describe a run of constants).
    MachineConstant {
        number: u32,
        constant: &'a MachineConstant,
    },
    Operation(&'a Operation),
    Cycle(&'a Cycle),
    Keyword(&'a Keyword),
    Function(&'a Function),
    SystemVariable(&'a SystemVariable),
    /// A system variable the catalogue does not list, known by its prefix.
    UndocumentedVariable(&'a VariablePrefix),
}

/// A query that matches nothing, with the closest entries.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NotFound {
    pub query: String,
    pub suggestions: Vec<String>,
}

impl Catalogue {
    /// Everything `query` can name. `R39` names both machine constant 39
    /// and program parameter 39: the parameter comes first when it has a
    /// special role (`R5`), else the machine constant. Prefixes pick one
    /// kind: `mc:39`, `param:39`, `op:48`, `group:G3`.
    pub fn explain(&self, query: &str) -> Result<Vec<Item<'_>>, NotFound> {
        self.items(query)
            .ok_or_else(|| NotFound { query: query.trim().to_owned(), suggestions: self.suggestions(query.trim()) })
    }

    /// What `explain` finds, without the suggestions it makes when it finds
    /// nothing (they compare the query with every entry): for hover.
    pub fn items(&self, query: &str) -> Option<Vec<Item<'_>>> {
        Some(self.lookup(query.trim())).filter(|items| !items.is_empty())
    }

    fn lookup(&self, query: &str) -> Vec<Item<'_>> {
        let upper = query.to_ascii_uppercase();
        let number_after = |prefix: &str| -> Option<u32> {
            let rest = upper.strip_prefix(prefix)?.trim_start_matches(':').trim();
            (!rest.is_empty() && rest.bytes().all(|b| b.is_ascii_digit())).then(|| rest.parse().ok()).flatten()
        };
        if let Some(code) = number_after("OP") {
            return self.operation(code).map(Item::Operation).into_iter().collect();
        }
        if let Some(number) = number_after("MC") {
            return self.machine_constant_item(number).into_iter().collect();
        }
        if let Some(number) = number_after("PARAM") {
            return self.is_parameter(number).then_some(Item::Parameter(number)).into_iter().collect();
        }
        if let Some(id) = upper.strip_prefix("GROUP:") {
            return self.group(id.trim()).map(Item::Group).into_iter().collect();
        }
        if upper.starts_with('$') {
            return match self.system_variable(&upper) {
                Some(SystemVariableInfo::Documented(variable)) => vec![Item::SystemVariable(variable)],
                Some(SystemVariableInfo::MachineData { constant, .. }) => {
                    vec![Item::MachineConstant { number: constant.number, constant }]
                }
                Some(SystemVariableInfo::Undocumented { prefix }) => vec![Item::UndocumentedVariable(prefix)],
                None => Vec::new(),
            };
        }
        if let Some(address) = self.address(&upper) {
            return vec![Item::Address(address)];
        }
        if let Some(code) = self.word_code(&upper) {
            return vec![Item::Code(code)];
        }
        let mut words: Vec<Item<'_>> = Vec::new();
        words.extend(self.keyword(&upper).map(Item::Keyword));
        words.extend(self.function(&upper).map(Item::Function));
        words.extend(
            self.operations.iter().filter(|op| op.symbol.as_deref() == Some(upper.as_str())).map(Item::Operation),
        );
        if crate::split_code(&upper).is_none() {
            words.extend(self.cycles_for(&upper).map(Item::Cycle));
        }
        if !words.is_empty() {
            return words;
        }
        let Some((letter, number)) = crate::split_code(&upper) else { return Vec::new() };
        // `split_code` gives an ASCII letter.
        match u8::try_from(letter).ok().and_then(|byte| self.role_of(byte)) {
            Some(AddressRole::Parameter) => {
                let constant = self.machine_constant_item(number);
                let parameter = self.is_parameter(number).then_some(Item::Parameter(number));
                // A parameter with a role of its own (R5, R95) is what a
                // programmer most likely means; otherwise the machine
                // constant (R39) is the one with something to say.
                let special = self.parameter_ranges_of(number).any(|r| r.status != ParameterStatus::Ordinary);
                if special {
                    parameter.into_iter().chain(constant).collect()
                } else {
                    constant.into_iter().chain(parameter).collect()
                }
            }
            Some(AddressRole::Function) => {
                let mut items = Vec::new();
                match self.code(letter, number) {
                    Some(code) => items.push(Item::Code(code)),
                    None => {
                        if let Some(group) = self.group_of(letter, number) {
                            items.push(Item::UnlistedCode { letter, number, group });
                        }
                    }
                }
                let name = format!("{letter}{number:02}");
                items.extend(self.cycles_for(&name).map(Item::Cycle));
                items
            }
            // `X10`, `F200`: the address.
            _ => self.address(&letter.to_string()).map(Item::Address).into_iter().collect(),
        }
    }

    fn machine_constant_item(&self, number: u32) -> Option<Item<'_>> {
        self.machine_constant(number).map(|constant| Item::MachineConstant { number, constant })
    }

    /// Up to three names close to `query`, for "did you mean".
    fn suggestions(&self, query: &str) -> Vec<String> {
        let query = query.to_ascii_uppercase();
        let mut names: Vec<String> = Vec::new();
        names.extend(self.codes.iter().map(|c| c.code.clone()));
        names.extend(self.groups.iter().map(|g| format!("group:{}", g.id)));
        names.extend(self.addresses.iter().map(|a| a.letter.clone()));
        names.extend((0..self.parameters.count).map(|n| format!("R{n}")));
        names.extend(self.machine_constants.iter().map(|c| format!("R{}", c.number)));
        names.extend(self.operations.iter().map(|op| format!("op:{}", op.code)));
        names.extend(self.operations.iter().filter_map(|op| op.symbol.clone()));
        names.extend(self.keywords.iter().map(|k| k.word.clone()));
        names.extend(self.functions.iter().map(|f| f.name.clone()));
        names.extend(self.system_variables.iter().map(|v| v.name.clone()));
        names.extend(self.cycles.iter().filter(|c| crate::split_code(&c.code).is_none()).map(|c| c.code.clone()));
        names.sort();
        names.dedup();
        let mut scored: Vec<(f64, String)> = names
            .into_iter()
            .map(|name| (strsim::normalized_damerau_levenshtein(&query, &name.to_ascii_uppercase()), name))
            .filter(|(score, _)| *score >= 0.5)
            .collect();
        scored.sort_by(|a, b| b.0.total_cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
        scored.into_iter().take(3).map(|(_, name)| name).collect()
    }
}
