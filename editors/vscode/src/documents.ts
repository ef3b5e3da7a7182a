// Which documents go to the server, and its answer about a document it has
// not taken. This module does not import `vscode`, so the tests run it in
// plain node.

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

/** JSON-RPC's error code for invalid parameters. */
const INVALID_PARAMS = -32602;

/**
 * Whether `error` is the server's answer to a request about a document it
 * has not taken, a program in a dialect it does not read: "<uri> is not
 * open".
 */
export function isNotOpenAnswer(error: unknown): boolean {
  if (typeof error !== 'object' || error === null) {
    return false;
  }
  const { code, message } = error as { code?: unknown; message?: unknown };
  return code === INVALID_PARAMS && typeof message === 'string' && message.endsWith(' is not open');
}
