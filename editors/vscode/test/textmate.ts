// The extension's TextMate grammars, run by the tokenizer VS Code uses.

import assert from 'node:assert/strict';
import { promises as fs } from 'node:fs';
import * as path from 'node:path';
import * as oniguruma from 'vscode-oniguruma';
import { type IGrammar, INITIAL, parseRawGrammar, Registry } from 'vscode-textmate';
import { manifest, root } from './manifest';

interface GrammarContribution {
  scopeName: string;
  path: string;
}

let registry: Registry | undefined;

/** The grammar `package.json` contributes under `scopeName`. */
export async function loadGrammar(scopeName: string): Promise<IGrammar> {
  if (registry === undefined) {
    await oniguruma.loadWASM(await fs.readFile(require.resolve('vscode-oniguruma/release/onig.wasm')));
    registry = new Registry({
      onigLib: Promise.resolve({
        createOnigScanner: (patterns) => new oniguruma.OnigScanner(patterns),
        createOnigString: (text) => new oniguruma.OnigString(text),
      }),
      loadGrammar: async (scope) => {
        const grammars = manifest.contributes.grammars as GrammarContribution[];
        const contributed = grammars.find((grammar) => grammar.scopeName === scope);
        if (contributed === undefined) {
          return null;
        }
        const file = path.join(root, contributed.path);
        return parseRawGrammar(await fs.readFile(file, 'utf8'), file);
      },
    });
  }
  const grammar = await registry.loadGrammar(scopeName);
  assert.ok(grammar, `the grammar ${scopeName} loads`);
  return grammar;
}

export interface Token {
  line: number;
  text: string;
  scopes: string[];
}

export function tokenize(grammar: IGrammar, text: string): Token[] {
  const tokens: Token[] = [];
  let state = INITIAL;
  text.split(/\r?\n/).forEach((line, number) => {
    const result = grammar.tokenizeLine(line, state);
    for (const token of result.tokens) {
      tokens.push({ line: number, text: line.slice(token.startIndex, token.endIndex), scopes: token.scopes });
    }
    state = result.ruleStack;
  });
  return tokens;
}

/** The innermost scope of each of `count` tokens, from the first place where the tokens spell `from`. */
export function scopesFrom(tokens: Token[], from: string, count: number): [string, string][] {
  const start = tokens.findIndex((_, index) => {
    let text = '';
    for (const token of tokens.slice(index)) {
      text += token.text;
      if (text.length >= from.length) {
        return text.startsWith(from);
      }
    }
    return false;
  });
  assert.notEqual(start, -1, `no tokens spell ${JSON.stringify(from)}`);
  return tokens.slice(start, start + count).map((token) => [token.text, token.scopes.at(-1) ?? '']);
}

/** Each token of `line` with its innermost scope. */
export function scopesOfLine(tokens: Token[], line: number): [string, string][] {
  return tokens.filter((token) => token.line === line).map((token) => [token.text, token.scopes.at(-1) ?? '']);
}

export function invalidTokens(tokens: Token[]): Token[] {
  return tokens.filter((token) => token.scopes.some((scope) => scope.startsWith('invalid.')));
}
