// A real session with `ncc lsp`, over the protocol connection that the
// language client is built on, started the way the extension starts it.
// The binary is $NCC_BIN, or `ncc` on PATH.

import assert from 'node:assert/strict';
import { type ChildProcess, execFileSync, spawn } from 'node:child_process';
import { promises as fs } from 'node:fs';
import * as os from 'node:os';
import * as path from 'node:path';
import { after, before, describe, test } from 'node:test';
import { pathToFileURL } from 'node:url';
import {
  createProtocolConnection,
  DidChangeTextDocumentNotification,
  DidOpenTextDocumentNotification,
  DiagnosticSeverity,
  ExecuteCommandRequest,
  ExitNotification,
  HoverRequest,
  InitializedNotification,
  InitializeRequest,
  type MarkupContent,
  type ProtocolConnection,
  PublishDiagnosticsNotification,
  type PublishDiagnosticsParams,
  type ServerCapabilities,
  ShutdownRequest,
  StreamMessageReader,
  StreamMessageWriter,
  TextDocumentSyncKind,
} from 'vscode-languageserver-protocol/node';
import { DOCUMENT_SELECTOR } from '../src/documents';
import { type Launch, readSettings, serverLaunch } from '../src/server';
import { failureMessage, PLOT_COMMAND, parsePlotted, plotArguments, plotMessage } from '../src/toolpath';
import { languageOf } from './manifest';

/** How long one answer from a debug build may take. */
const TIMEOUT_MS = 20_000;

// The comment before the error holds a character outside the Basic
// Multilingual Plane: one character, two UTF-16 code units, four bytes.
// Positions agree only if the server counts UTF-16 units as the protocol says.
const PROGRAM = ['%1', 'N10 G00 "\u{1F527}" X- 5', 'N20 M30', '*', ''].join('\n');
const ERROR_LINE = 1;
const SIGN_COLUMN = 'N10 G00 "\u{1F527}" X'.length;

let scratch: string;
let launch: Launch;
let server: ChildProcess;
let exited: Promise<number | null>;
let connection: ProtocolConnection;
let stderr = '';
const published: PublishDiagnosticsParams[] = [];
const waiters: (() => void)[] = [];

before(async () => {
  scratch = await fs.mkdtemp(path.join(os.tmpdir(), 'ncc-vscode-session-'));
  await fs.mkdir(path.join(scratch, 'machine'));
  await fs.mkdir(path.join(scratch, 'programs'));
  // The machine configuration lies outside the program's directories, so
  // only the initialization option can bring it in.
  await fs.writeFile(path.join(scratch, 'machine', 'ncc.toml'), '[rules]\nspace-after-sign = "warning"\n');

  // NCC_BIN is a path from where the tests run; the setting's relative
  // paths start at the workspace folder.
  const bin = process.env['NCC_BIN'];
  const settings = readSettings(
    (key) => ({ 'server.path': bin && path.resolve(bin), 'machine.configFile': 'machine/ncc.toml' })[key],
  );
  const found = await serverLaunch(settings, {
    base: scratch,
    home: os.homedir(),
    env: process.env,
    platform: process.platform,
  });
  if (!found.ok) {
    assert.fail(`No ncc to test against: ${found.message} Set NCC_BIN to the binary, e.g. target/debug/ncc.`);
  }
  launch = found.value;
  assert.deepEqual(launch.args, ['lsp', '--log-level', 'warn']);
  assert.match(launch.version, /^ncc \d+\.\d+\.\d+/);

  server = spawn(launch.command, launch.args, { stdio: ['pipe', 'pipe', 'pipe'] });
  // 'close' comes after stderr has been read to its end.
  exited = new Promise((resolve) => server.once('close', (code) => resolve(code)));
  server.stderr?.on('data', (chunk: Buffer) => (stderr += chunk.toString()));
  assert.ok(server.stdout && server.stdin);
  connection = createProtocolConnection(new StreamMessageReader(server.stdout), new StreamMessageWriter(server.stdin));
  connection.onNotification(PublishDiagnosticsNotification.type, (params) => {
    published.push(params);
    waiters.splice(0).forEach((wake) => wake());
  });
  connection.listen();
});

after(async () => {
  connection?.dispose();
  if (server?.exitCode === null) {
    server.kill();
  }
  await fs.rm(scratch, { recursive: true, force: true });
});

/**
 * Resolves with `promise`, or fails when the server exits first or after
 * TIMEOUT_MS, saying what was awaited and what the server wrote to stderr.
 */
async function within<T>(what: string, promise: Promise<T>, exitExpected = false): Promise<T> {
  let timer: NodeJS.Timeout | undefined;
  const failures = [
    new Promise<never>((_, reject) => {
      timer = setTimeout(() => reject(new Error(`nothing came within ${TIMEOUT_MS} ms`)), TIMEOUT_MS);
    }),
  ];
  if (!exitExpected) {
    failures.push(
      exited.then((code) => {
        throw new Error(`ncc lsp exited with ${code}`);
      }),
    );
  }
  try {
    return await Promise.race([promise, ...failures]);
  } catch (error) {
    // Let the server finish writing, in case it is on its way out.
    await Promise.race([exited, new Promise((resolve) => setTimeout(resolve, 1000))]);
    const reason = error instanceof Error ? error.message : String(error);
    throw new Error(`waiting for the ${what}: ${reason}\nncc lsp wrote to stderr:\n${stderr}`);
  } finally {
    clearTimeout(timer);
  }
}

/** The first published diagnostics, since the session began, for which `accept` holds. */
async function diagnostics(
  what: string,
  accept: (params: PublishDiagnosticsParams) => boolean,
): Promise<PublishDiagnosticsParams> {
  const found = new Promise<PublishDiagnosticsParams>((resolve) => {
    const look = () => {
      const match = published.find(accept);
      if (match) {
        resolve(match);
      } else {
        waiters.push(look);
      }
    };
    look();
  });
  try {
    return await within(what, found);
  } catch (error) {
    throw new Error(`${error instanceof Error ? error.message : error}\npublished: ${JSON.stringify(published)}`);
  }
}

describe('a session with ncc lsp', () => {
  const uri = () => pathToFileURL(path.join(scratch, 'programs', 'P1.NCP')).href;
  let capabilities: ServerCapabilities;

  test('initialize: UTF-16 positions and incremental sync', async () => {
    const initialized = await within(
      'answer to initialize',
      connection.sendRequest(InitializeRequest.type, {
        processId: process.pid,
        clientInfo: { name: 'ncc session test' },
        rootUri: pathToFileURL(scratch).href,
        workspaceFolders: [{ uri: pathToFileURL(scratch).href, name: 'session' }],
        initializationOptions: launch.initializationOptions,
        capabilities: {
          general: { positionEncodings: ['utf-16'] },
          textDocument: {
            synchronization: { dynamicRegistration: false },
            publishDiagnostics: { relatedInformation: true, versionSupport: true, tagSupport: { valueSet: [1, 2] } },
            hover: { contentFormat: ['markdown', 'plaintext'] },
          },
        },
      }),
    );
    capabilities = initialized.capabilities;
    await connection.sendNotification(InitializedNotification.type, {});
    assert.ok([undefined, 'utf-16'].includes(capabilities.positionEncoding), 'UTF-16 positions');
    const sync = capabilities.textDocumentSync;
    assert.equal(typeof sync === 'object' ? sync.change : sync, TextDocumentSyncKind.Incremental);
    if (typeof sync === 'object') {
      assert.equal(sync.openClose, true);
    }
  });

  test('announces the features the editors rely on', () => {
    const providers = [
      'hoverProvider',
      'definitionProvider',
      'referencesProvider',
      'documentSymbolProvider',
      'foldingRangeProvider',
      'completionProvider',
      'codeActionProvider',
      'inlayHintProvider',
      'documentFormattingProvider',
    ] as const;
    const missing: string[] = providers.filter((provider) => !capabilities[provider]);
    if (!capabilities.executeCommandProvider?.commands.includes(PLOT_COMMAND)) {
      missing.push(`executeCommandProvider ${PLOT_COMMAND}`);
    }
    const semanticTokens = capabilities.semanticTokensProvider;
    if (!semanticTokens?.full || semanticTokens.legend.tokenTypes.length === 0) {
      missing.push('semanticTokensProvider');
    }
    assert.deepEqual(missing, [], 'capabilities the server does not announce');
  });

  test('publishes the diagnostics of an opened program, at the level the machine file sets', async () => {
    await connection.sendNotification(DidOpenTextDocumentNotification.type, {
      textDocument: { uri: uri(), languageId: 'cnc8x6', version: 1, text: PROGRAM },
    });
    const opened = await diagnostics('diagnostics for the opened program', (p) => p.uri === uri() && p.version === 1);
    const spaceAfterSign = opened.diagnostics.find((d) => d.code === 'S003');
    assert.ok(spaceAfterSign, `S003 among ${JSON.stringify(opened.diagnostics)}`);
    assert.equal(spaceAfterSign.source, 'ncc');
    assert.equal(spaceAfterSign.severity, DiagnosticSeverity.Warning, 'the level from the machine file');
    assert.equal(spaceAfterSign.range.start.line, ERROR_LINE);
    assert.ok(
      spaceAfterSign.range.start.character >= SIGN_COLUMN && spaceAfterSign.range.end.character <= SIGN_COLUMN + 3,
      `the range ${JSON.stringify(spaceAfterSign.range)} lies on "- 5", columns ${SIGN_COLUMN}-${SIGN_COLUMN + 3}`,
    );
  });

  test('hover over a G code shows its documentation', async () => {
    const hover = await within(
      'hover',
      connection.sendRequest(HoverRequest.type, {
        textDocument: { uri: uri() },
        position: { line: ERROR_LINE, character: 5 },
      }),
    );
    assert.ok(hover, 'a hover over G00');
    const contents = hover.contents as MarkupContent;
    assert.equal(contents.kind, 'markdown');
    const explained = execFileSync(launch.command, ['explain', 'G00'], { encoding: 'utf8' });
    const title = explained.split('\n').find((line) => line.trim() !== '');
    assert.ok(title && contents.value.includes(title.trim()), `hover ${JSON.stringify(contents.value)} has ${title}`);
  });

  test('an edit that fixes the error clears the diagnostics', async () => {
    await connection.sendNotification(DidChangeTextDocumentNotification.type, {
      textDocument: { uri: uri(), version: 2 },
      contentChanges: [
        {
          range: {
            start: { line: ERROR_LINE, character: SIGN_COLUMN },
            end: { line: ERROR_LINE, character: SIGN_COLUMN + 3 },
          },
          text: '-5',
        },
      ],
    });
    await diagnostics(
      'empty diagnostics after the fix',
      (p) => p.uri === uri() && p.version === 2 && p.diagnostics.length === 0,
    );
  });

  test('ncc.plot draws the edited text, as the toolpath view asks for it', async () => {
    // The fixed text: N10 is a rapid move to X-5 on line 2.
    const answer = await within(
      'answer to ncc.plot',
      connection.sendRequest(ExecuteCommandRequest.type, { command: PLOT_COMMAND, arguments: [uri()] }),
    );
    const plotted = parsePlotted(answer);
    assert.ok(plotted, `a picture in ${JSON.stringify(answer)}`);
    assert.match(plotted.svg, /<path data-line="2" d="[^"]*"[^>]*stroke-dasharray/);
    const message = plotMessage(plotted);
    assert.ok(message.type === 'plot' && /^Total time \d+:\d\d:\d\d\.\d{3}$/.test(message.summary), message.type);

    const notOpen = pathToFileURL(path.join(scratch, 'programs', 'P2.NCP')).href;
    const failed = await within(
      'error of ncc.plot',
      connection.sendRequest(ExecuteCommandRequest.type, { command: PLOT_COMMAND, arguments: [notOpen] }).then(
        () => assert.fail('ncc.plot of a document that is not open succeeded'),
        (error: unknown) => error,
      ),
    );
    const shown = failureMessage(failed);
    assert.match(shown.message, /P2\.NCP is not open/);
    assert.equal(shown.svg, undefined);
  });

  test('a Haas lathe program is read in its dialect: its findings and hover', async () => {
    const file = 'O1234.nc';
    const languageId = languageOf(file);
    assert.equal(languageId, 'haas-lathe');
    const program = pathToFileURL(path.join(scratch, 'programs', file)).href;
    const text = '%\nO1234 (SHAFT)\nG71 P10 Q90 U0.4 W0.1 D2. F0.25\nN10 G00 X20.\nG01 Z-20.\nM30\n%\n';
    await connection.sendNotification(DidOpenTextDocumentNotification.type, {
      textDocument: { uri: program, languageId, version: 1, text },
    });
    const opened = await diagnostics(`the findings of ${file}`, (p) => p.uri === program && p.version === 1);
    assert.deepEqual(
      opened.diagnostics.map((d) => [d.code, d.range.start.line, d.range.start.character]),
      [['L028', 2, 8]],
    );
    const hover = await within(
      `answer to hover on ${file}`,
      connection.sendRequest(HoverRequest.type, {
        textDocument: { uri: program },
        position: { line: 2, character: 1 },
      }),
    );
    assert.match(JSON.stringify(hover), /G71 — Longitudinal roughing cycle/);

    // The toolpath view's lathe views: the server's default, then the one chosen.
    const turned = pathToFileURL(path.join(scratch, 'programs', 'O1235.nc')).href;
    await connection.sendNotification(DidOpenTextDocumentNotification.type, {
      textDocument: { uri: turned, languageId, version: 1, text: '%\nO1235\nG00 X50. Z2.\nG01 Z-20. F0.2\nM30\n%\n' },
    });
    for (const [chosen, drawn] of [
      [undefined, 'diameter'],
      ['radius', 'radius'],
    ] as const) {
      const answer = await within(
        `answer to ncc.plot of ${file} in view ${chosen}`,
        connection.sendRequest(ExecuteCommandRequest.type, {
          command: PLOT_COMMAND,
          arguments: plotArguments(turned, chosen),
        }),
      );
      const plotted = parsePlotted(answer);
      assert.equal(plotted?.view, drawn, JSON.stringify(answer));
      assert.match(plotted?.svg ?? '', new RegExp(`ZX plane, X as a ${drawn}`));
    }
  });

  test('a Sinumerik program gets its syntax errors and hover from the catalogue', async () => {
    const file = 'MAIN.MPF';
    // The language VS Code gives the file, which the client hands over.
    const languageId = languageOf(file);
    assert.equal(languageId, 'sinumerik', file);
    assert.ok(DOCUMENT_SELECTOR.some((selector) => selector.scheme === 'file' && selector.language === languageId));
    const program = pathToFileURL(path.join(scratch, 'programs', file)).href;
    await connection.sendNotification(DidOpenTextDocumentNotification.type, {
      textDocument: { uri: program, languageId, version: 1, text: 'G0 X10 Z2\nR1=(5+2\nM30\n' },
    });
    const opened = await diagnostics(`the findings on ${file}`, (p) => p.uri === program && p.version === 1);
    assert.deepEqual(
      opened.diagnostics.map((d) => [d.code, d.range.start]),
      [['S029', { line: 1, character: 3 }]],
    );
    const hover = await within(
      `answer to hover on ${file}`,
      connection.sendRequest(HoverRequest.type, {
        textDocument: { uri: program },
        position: { line: 0, character: 0 },
      }),
    );
    assert.match(JSON.stringify(hover), /G0 — /, `hover on ${file}`);
  });

  test('shutdown and exit end the server with status 0', async () => {
    await within('answer to shutdown', connection.sendRequest(ShutdownRequest.type));
    await connection.sendNotification(ExitNotification.type);
    assert.equal(await within('exit', exited, true), 0);
    // The server may publish a version in steps; none of them kept the error.
    const afterFix = published.filter((p) => p.uri === uri() && p.version === 2);
    assert.deepEqual(
      afterFix.map((p) => p.diagnostics),
      afterFix.map(() => []),
    );
  });
});
