// The language contribution: which files become CNC8x6 documents, and what
// the language configuration makes of them.

import assert from 'node:assert/strict';
import { existsSync, readFileSync } from 'node:fs';
import * as path from 'node:path';
import { describe, test } from 'node:test';
import { minimatch } from 'minimatch';

const root = path.resolve(__dirname, '..', '..');
const manifest = JSON.parse(readFileSync(path.join(root, 'package.json'), 'utf8'));
const [language] = manifest.contributes.languages;

/**
 * Whether VS Code gives a file the language: it compares lowercased
 * extensions, and lowercased file-name patterns without a slash with the
 * lowercased base name.
 */
function isCnc8x6(file: string): boolean {
  const name = path.basename(file).toLowerCase();
  return (
    language.extensions.some((ext: string) => name.endsWith(ext.toLowerCase())) ||
    language.filenamePatterns.some((pattern: string) => minimatch(name, pattern.toLowerCase(), { dot: true }))
  );
}

describe('language contribution', () => {
  test('is cnc8x6, with a grammar and a configuration that exist', () => {
    assert.equal(language.id, 'cnc8x6');
    assert.ok(existsSync(path.join(root, language.configuration)));
    const [grammar] = manifest.contributes.grammars;
    assert.equal(grammar.language, 'cnc8x6');
    assert.ok(existsSync(path.join(root, grammar.path)));
  });

  test('takes partprograms and macrocycle files', () => {
    for (const file of ['examples/milling/pocket.NCP', 'a.ncp', 'PCYKLYDG.NCP', 'L1', 'L9001', 'dir/l12', 'L0100', 'L12.NCP']) {
      assert.ok(isCnc8x6(file), file);
    }
  });

  test('leaves other files alone', () => {
    const others = ['L', 'LICENSE', 'Lx1', 'L1a', 'L12345', 'L9001.txt', 'L9001.bak', 'README.md', 'NCP', 'a.NCP.orig', 'ML9001'];
    for (const file of others) {
      assert.ok(!isCnc8x6(file), file);
    }
  });
});

describe('language configuration', () => {
  const configuration = JSON.parse(readFileSync(path.join(root, language.configuration), 'utf8'));

  test('comments a line with a double quote', () => {
    assert.deepEqual(configuration.comments, { lineComment: '"' });
  });

  test('takes a word with its value, a parameter or prose as one word', () => {
    // VS Code adds the global flag to the configured ones.
    const word = new RegExp(configuration.wordPattern.pattern, configuration.wordPattern.flags + 'g');
    const text = 'N10 G01X-12.5 FR10 R10=250. &0010 %101 "DRÁŽKA R8"';
    assert.deepEqual(text.match(word), ['N10', 'G01', 'X-12.5', 'FR10', 'R10', '250.', '&0010', '%101', 'DRÁŽKA', 'R8']);
  });
});
