// The extension's manifest, and which of its languages VS Code gives a file.

import { readFileSync } from 'node:fs';
import * as path from 'node:path';
import { minimatch } from 'minimatch';

export const root = path.resolve(__dirname, '..', '..');
export const manifest = JSON.parse(readFileSync(path.join(root, 'package.json'), 'utf8'));

interface Language {
  id: string;
  extensions?: string[];
  filenamePatterns?: string[];
}

/**
 * The language VS Code gives a file, if any: it compares lowercased
 * extensions, and lowercased file-name patterns without a slash with the
 * lowercased base name. Fails when two languages take the file.
 */
export function languageOf(file: string): string | undefined {
  const name = path.basename(file).toLowerCase();
  const taking = (manifest.contributes.languages as Language[]).filter(
    (language) =>
      (language.extensions ?? []).some((ext) => name.endsWith(ext.toLowerCase())) ||
      (language.filenamePatterns ?? []).some((pattern) => minimatch(name, pattern.toLowerCase(), { dot: true })),
  );
  if (taking.length > 1) {
    throw new Error(`${file} is taken by ${taking.map((language) => language.id).join(' and ')}`);
  }
  return taking[0]?.id;
}
