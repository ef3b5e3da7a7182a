// Which documents go to the server. This module does not import `vscode`,
// so the tests run it in plain node.

/**
 * The languages the extension contributes, one per control, named as ncc
 * names its dialects. The server picks each file's dialect itself, from the
 * file's name and its project's `ncc.toml`; of a program in a dialect it
 * does not read it says so in one diagnostic.
 */
export const LANGUAGES = ['cnc8x6', 'haas-lathe', 'sinumerik'] as const;

/** The documents the language client hands to the server. */
export const DOCUMENT_SELECTOR = [
  ...LANGUAGES.map((language) => ({ scheme: 'file', language })),
  // The server reads a document without a file name as CNC8x6, whatever
  // language the editor gave it.
  { scheme: 'untitled', language: 'cnc8x6' },
];

/**
 * The languages the toolpath view is offered for: the dialects with an
 * executor. Of a document in a dialect it does not read, the server answers
 * `ncc.plot` with an error, which the view shows.
 */
export const TOOLPATH_LANGUAGES: readonly (typeof LANGUAGES)[number][] = ['cnc8x6', 'haas-lathe'];
