//! The files the server knows: one analysis host per `ncc.toml` (as
//! `ncc check` groups them), holding the programs and macrocycle files of
//! the workspace folders and every open document.

use std::{
    collections::HashMap,
    path::{Path, PathBuf},
};

use ncc_analysis::{AnalysisHost, Config, Dialect, FileId, NavigationTarget, Renaming};
use tower_lsp_server::ls_types::{self as lsp, Uri};

use super::convert::LineMap;
use crate::check;

#[derive(Debug, Default)]
pub(crate) struct Workspaces {
    /// The dialect of every document, when the server was started with one.
    forced_dialect: Option<Dialect>,
    /// Each project's configuration, read once, or the one the client named
    /// for every document.
    projects: check::Projects,
    list: Vec<Workspace>,
}

/// The files of one dialect in one project.
#[derive(Debug)]
struct Workspace {
    config_path: Option<PathBuf>,
    dialect: Dialect,
    host: AnalysisHost,
    /// Files by the path the analysis knows them by.
    files: HashMap<String, FileId>,
    /// The address of each file, for answers that point into it.
    uris: HashMap<FileId, Uri>,
}

/// The path the analysis knows a document by: its file path, or the URI
/// itself for documents that are not files (`untitled:`).
fn document_path(uri: &Uri) -> (String, Option<PathBuf>) {
    match uri.to_file_path() {
        Some(path) => (path.display().to_string(), Some(path.into_owned())),
        None => (uri.as_str().to_owned(), None),
    }
}

/// What opening a document gave: it is analysed in `dialect` as `file` of
/// workspace `index`; `errors` are about files read on the way.
pub(crate) struct Opened {
    pub index: usize,
    pub dialect: Dialect,
    pub file: FileId,
    pub errors: Vec<String>,
}

impl Workspaces {
    pub fn new(forced_dialect: Option<Dialect>) -> Workspaces {
        Workspaces { forced_dialect, ..Workspaces::default() }
    }

    pub fn configure(&mut self, config_file: Option<PathBuf>) {
        self.projects = check::Projects::with_config(config_file);
    }

    pub fn get(&self, index: usize) -> &AnalysisHost {
        &self.list[index].host
    }

    pub fn host_mut(&mut self, index: usize) -> &mut AnalysisHost {
        &mut self.list[index].host
    }

    /// The `ncc.toml` whose configuration workspace `index` has, if any.
    pub fn config_path(&self, index: usize) -> Option<&Path> {
        self.list[index].config_path.as_deref()
    }

    /// The `ncc.toml` that applies to the program at `path` and its
    /// dialect (a document that is no file, `untitled:`, has the default
    /// one).
    fn project_of(&mut self, path: Option<&Path>) -> (Option<PathBuf>, Dialect) {
        let dialect = self.projects.dialects(path).of_given(path.unwrap_or(Path::new("")), self.forced_dialect);
        (self.projects.config_path(path), dialect)
    }

    /// The workspace of `dialect` in the project of `config_path`; an error
    /// reading its configuration is returned when the workspace is made,
    /// and the defaults used.
    fn workspace_for(&mut self, config_path: Option<PathBuf>, dialect: Dialect, errors: &mut Vec<String>) -> usize {
        if let Some(index) = self.list.iter().position(|w| w.config_path == config_path && w.dialect == dialect) {
            return index;
        }
        let config = self.projects.config(config_path.as_deref()).clone().unwrap_or_else(|error| {
            errors.push(error);
            Config::default()
        });
        self.list.push(Workspace {
            config_path,
            dialect,
            host: AnalysisHost::in_dialect(dialect, config),
            files: HashMap::new(),
            uris: HashMap::new(),
        });
        self.list.len() - 1
    }

    /// Adds a file read from disk unless its workspace has it.
    fn add_from_disk(&mut self, path: &Path, errors: &mut Vec<String>) {
        let (config_path, dialect) = self.project_of(Some(path));
        let index = self.workspace_for(config_path, dialect, errors);
        let workspace = &mut self.list[index];
        let name = path.display().to_string();
        if workspace.files.contains_key(&name) {
            return;
        }
        match check::read_program(path) {
            Ok(text) => {
                let file = workspace.host.add_file(name.clone(), text);
                workspace.files.insert(name, file);
                if let Some(uri) = Uri::from_file_path(path) {
                    workspace.uris.insert(file, uri);
                }
            }
            Err(error) => errors.push(format!("{}: {error}", path.display())),
        }
    }

    /// Indexes the partprograms and macrocycle files under the workspace
    /// folders, so that calls resolve across files.
    pub fn load_roots(&mut self, roots: &[PathBuf]) -> Vec<String> {
        let check::Found { files, mut failures, .. } =
            check::collect_files(roots, &mut self.projects, self.forced_dialect);
        for (path, _) in files {
            self.add_from_disk(&path, &mut failures);
        }
        failures
    }

    /// Opens a document: its text replaces what was read from disk.
    /// Macrocycle files beside it join the workspace.
    pub fn open(&mut self, uri: &Uri, text: String) -> Opened {
        let (name, path) = document_path(uri);
        let mut errors = Vec::new();
        let (config_path, dialect) = self.project_of(path.as_deref());
        let index = self.workspace_for(config_path, dialect, &mut errors);
        if let Some(path) = &path {
            let beside = check::macrocycles_beside(&[(path.clone(), String::new())]);
            for (macrocycle, _) in beside {
                self.add_from_disk(&macrocycle, &mut errors);
            }
        }
        let workspace = &mut self.list[index];
        let file = match workspace.files.get(&name) {
            Some(&file) => {
                workspace.host.set_text(file, text);
                file
            }
            None => {
                let file = workspace.host.add_file(name.clone(), text);
                workspace.files.insert(name, file);
                file
            }
        };
        workspace.uris.insert(file, uri.clone());
        Opened { index, dialect, file, errors }
    }

    /// Closes a document: the file on disk takes its place again, or the
    /// file leaves the workspace when there is none.
    pub fn close(&mut self, index: usize, uri: &Uri, file: FileId) {
        let (name, path) = document_path(uri);
        let workspace = &mut self.list[index];
        match path.as_deref().map(check::read_program) {
            Some(Ok(text)) => workspace.host.set_text(file, text),
            _ => {
                workspace.host.remove_file(file);
                workspace.files.remove(&name);
                workspace.uris.remove(&file);
            }
        }
    }

    /// Converts ranges of the workspace's files to locations.
    pub fn addresses(&self, index: usize) -> Addresses<'_> {
        let workspace = &self.list[index];
        Addresses { uris: &workspace.uris, analysis: workspace.host.analysis(), maps: HashMap::new() }
    }
}

/// Locations in a workspace's files; each file's line map is built once,
/// however many ranges point into it.
pub(crate) struct Addresses<'a> {
    uris: &'a HashMap<FileId, Uri>,
    analysis: ncc_analysis::Analysis,
    maps: HashMap<FileId, LineMap>,
}

impl Addresses<'_> {
    /// The file's address and line map, if it has an address.
    fn of(&mut self, file: FileId) -> Option<(Uri, &LineMap)> {
        let uri = self.uris.get(&file)?.clone();
        let map = self.maps.entry(file).or_insert_with(|| LineMap::new(self.analysis.text(file)));
        Some((uri, map))
    }

    pub fn location(&mut self, file: FileId, range: ncc_analysis::TextRange) -> Option<lsp::Location> {
        let (uri, map) = self.of(file)?;
        Some(lsp::Location::new(uri, map.range(range)))
    }

    /// The edits of a rename in the protocol's terms: the changes of each
    /// file, and the files it renames after them.
    pub fn workspace_edit(&mut self, renaming: &Renaming) -> lsp::WorkspaceEdit {
        let mut changes = Vec::new();
        for (file, edits) in &renaming.edits {
            if let Some((uri, map)) = self.of(*file) {
                let edits = edits
                    .iter()
                    .map(|edit| lsp::TextEdit { range: map.range(edit.delete), new_text: edit.insert.clone() });
                changes.push((uri, edits.collect::<Vec<_>>()));
            }
        }
        if renaming.moved.is_empty() {
            return lsp::WorkspaceEdit { changes: Some(changes.into_iter().collect()), ..Default::default() };
        }
        let mut operations: Vec<lsp::DocumentChangeOperation> = changes
            .into_iter()
            .map(|(uri, edits)| {
                lsp::DocumentChangeOperation::Edit(lsp::TextDocumentEdit {
                    text_document: lsp::OptionalVersionedTextDocumentIdentifier { uri, version: None },
                    edits: edits.into_iter().map(lsp::OneOf::Left).collect(),
                })
            })
            .collect();
        for (file, path) in &renaming.moved {
            if let (Some(old_uri), Some(new_uri)) = (self.uris.get(file), Uri::from_file_path(path)) {
                operations.push(lsp::DocumentChangeOperation::Op(lsp::ResourceOp::Rename(lsp::RenameFile {
                    old_uri: old_uri.clone(),
                    new_uri,
                    options: None,
                    annotation_id: None,
                })));
            }
        }
        lsp::WorkspaceEdit {
            document_changes: Some(lsp::DocumentChanges::Operations(operations)),
            ..Default::default()
        }
    }

    pub fn location_link(&mut self, target: NavigationTarget) -> Option<lsp::LocationLink> {
        let (uri, map) = self.of(target.file)?;
        Some(lsp::LocationLink {
            origin_selection_range: None,
            target_uri: uri,
            target_range: map.range(target.range),
            target_selection_range: map.range(target.focus),
        })
    }
}
