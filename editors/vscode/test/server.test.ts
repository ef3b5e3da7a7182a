// Server discovery, settings and the command line, on a scratch directory.

import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { promises as fs } from 'node:fs';
import * as os from 'node:os';
import * as path from 'node:path';
import { PassThrough } from 'node:stream';
import { after, before, describe, test } from 'node:test';
import {
  type Environment,
  findServer,
  initializationOptions,
  readSettings,
  resolveSettingPath,
  serverLaunch,
  ServerStderr,
  serverVersion,
  type Settings,
  startFailure,
} from '../src/server';

const posix = process.platform !== 'win32';

let scratch: string;
let bin: string;
let other: string;
let old: string;

before(async () => {
  scratch = await fs.mkdtemp(path.join(os.tmpdir(), 'ncc-vscode-'));
  bin = path.join(scratch, 'bin');
  other = path.join(scratch, 'other');
  await fs.mkdir(bin);
  await fs.mkdir(other);
  await fs.mkdir(path.join(scratch, 'bin', 'dir'));
  await fs.writeFile(
    path.join(bin, 'ncc'),
    '#!/bin/sh\n[ "$*" = "lsp --version" ] && echo "ncc 9.8.7" && exit 0\nexit 2\n',
    { mode: 0o755 },
  );
  await fs.writeFile(path.join(other, 'ncc'), 'not executable\n', { mode: 0o644 });
  // An ncc from before the language server.
  old = path.join(scratch, 'old-ncc');
  await fs.writeFile(old, "#!/bin/sh\necho \"error: unrecognized subcommand '$1'\" >&2\nexit 2\n", { mode: 0o755 });
});

after(async () => {
  await fs.rm(scratch, { recursive: true, force: true });
});

function settings(overrides: Partial<Settings> = {}): Settings {
  return { serverPath: '', logLevel: 'warn', configFile: '', cycleTimeHints: 'perBlock', ...overrides };
}

function environment(overrides: Partial<Environment> = {}): Environment {
  return { base: scratch, home: scratch, env: { PATH: '' }, platform: process.platform, ...overrides };
}

describe('readSettings', () => {
  test('reads the keys below ncc.', () => {
    const values: Record<string, unknown> = {
      'server.path': ' /opt/ncc/bin/ncc ',
      'server.logLevel': 'debug',
      'machine.configFile': 'ncc.toml',
      'cycleTime.inlayHints': 'cumulative',
    };
    assert.deepEqual(
      readSettings((key) => values[key]),
      { serverPath: '/opt/ncc/bin/ncc', logLevel: 'debug', configFile: 'ncc.toml', cycleTimeHints: 'cumulative' },
    );
  });

  test('takes unset and mistyped values as their defaults', () => {
    assert.deepEqual(readSettings(() => undefined), settings());
    const values: Record<string, unknown> = {
      'server.path': 42,
      'server.logLevel': 'verbose',
      'cycleTime.inlayHints': 'everywhere',
    };
    assert.deepEqual(readSettings((key) => values[key]), settings());
  });
});

describe('resolveSettingPath', () => {
  test('expands ~ and resolves relative paths against the workspace folder', () => {
    const env = environment({ base: path.join(scratch, 'work'), home: path.join(scratch, 'home') });
    assert.equal(resolveSettingPath('~/bin/ncc', env), path.join(scratch, 'home', 'bin', 'ncc'));
    assert.equal(resolveSettingPath('~', env), path.join(scratch, 'home'));
    assert.equal(resolveSettingPath('target/debug/ncc', env), path.join(scratch, 'work', 'target', 'debug', 'ncc'));
    assert.equal(resolveSettingPath(path.join(scratch, 'x', '..', 'ncc'), env), path.join(scratch, 'ncc'));
  });

  test('leaves a relative path unresolved without a workspace folder', () => {
    assert.equal(resolveSettingPath('ncc', environment({ base: undefined })), undefined);
  });
});

describe('findServer', () => {
  test('finds ncc on PATH, skipping directories where it is not executable', { skip: !posix }, async () => {
    const env = environment({ env: { PATH: [path.join(scratch, 'missing'), other, bin].join(path.delimiter) } });
    assert.deepEqual(await findServer(settings(), env), { ok: true, value: path.join(bin, 'ncc') });
  });

  test('says how to install ncc when it is not on PATH', async () => {
    const result = await findServer(settings(), environment({ env: { PATH: other + path.delimiter } }));
    assert.equal(result.ok, false);
    assert.ok(!result.ok && result.setting === 'ncc.server.path');
    assert.match(!result.ok ? result.message : '', /not found on the PATH.*cargo install --path crates\/lsp.*ncc\.server\.path/);
  });

  test('on Windows, looks for ncc with the extensions in PATHEXT', async () => {
    const env = environment({ platform: 'win32', env: { PATH: other, PATHEXT: '.COM;.EXE' } });
    assert.equal((await findServer(settings(), env)).ok, false, 'a file without extension does not run');
    await fs.writeFile(path.join(other, 'ncc.EXE'), '');
    assert.deepEqual(await findServer(settings(), env), { ok: true, value: path.join(other, 'ncc.EXE') });
    await fs.rm(path.join(other, 'ncc.EXE'));
  });

  test('uses the configured path, relative to the workspace folder', async () => {
    assert.deepEqual(await findServer(settings({ serverPath: 'bin/ncc' }), environment()), {
      ok: true,
      value: path.join(bin, 'ncc'),
    });
  });

  test('explains what is wrong with the configured path', async () => {
    const cases: [string, string][] = [
      [path.join(scratch, 'nothing'), 'does not exist'],
      [path.join(bin, 'dir'), 'is not a file'],
    ];
    if (posix) {
      cases.push([path.join(other, 'ncc'), 'is not executable']);
    }
    for (const [serverPath, problem] of cases) {
      assert.deepEqual(await findServer(settings({ serverPath }), environment()), {
        ok: false,
        setting: 'ncc.server.path',
        message: `ncc.server.path names ${serverPath}, which ${problem}.`,
      });
    }
    assert.deepEqual(await findServer(settings({ serverPath: 'ncc' }), environment({ base: undefined })), {
      ok: false,
      setting: 'ncc.server.path',
      message: 'ncc.server.path is the relative path ncc, but no folder is open to resolve it against.',
    });
  });
});

describe('initializationOptions', () => {
  test('passes the configuration file as an absolute path, or nothing', () => {
    const cycleTime = { inlayHints: 'perBlock' };
    assert.deepEqual(initializationOptions(settings(), environment()), { ok: true, value: { cycleTime } });
    assert.deepEqual(initializationOptions(settings({ configFile: 'machines/ncc.toml' }), environment()), {
      ok: true,
      value: { configFile: path.join(scratch, 'machines', 'ncc.toml'), cycleTime },
    });
    const result = initializationOptions(settings({ configFile: 'ncc.toml' }), environment({ base: undefined }));
    assert.equal(!result.ok && result.setting, 'ncc.machine.configFile');
  });
});

describe('serverVersion', { skip: !posix }, () => {
  test('is what `ncc lsp --version` prints', async () => {
    assert.deepEqual(await serverVersion(path.join(bin, 'ncc')), { ok: true, value: 'ncc 9.8.7' });
  });

  test('says what a binary without a language server answered', async () => {
    assert.deepEqual(await serverVersion(old), {
      ok: false,
      setting: 'ncc.server.path',
      message:
        `${old} is not an ncc with a language server: ` +
        `"ncc lsp --version" answered "error: unrecognized subcommand 'lsp'". ` +
        'Install a current ncc with "cargo install --path crates/lsp", or set ncc.server.path to one.',
    });
  });
});

describe('serverLaunch', { skip: !posix }, () => {
  test('runs `ncc lsp` with the log level', async () => {
    const launch = await serverLaunch(
      settings({ serverPath: path.join(bin, 'ncc'), logLevel: 'trace', configFile: '~/ncc.toml' }),
      environment(),
    );
    assert.deepEqual(launch, {
      ok: true,
      value: {
        command: path.join(bin, 'ncc'),
        args: ['lsp', '--log-level', 'trace'],
        initializationOptions: {
          configFile: path.join(scratch, 'ncc.toml'),
          cycleTime: { inlayHints: 'perBlock' },
        },
        version: 'ncc 9.8.7',
      },
    });
  });

  test('reports the first setting that keeps the server from starting', async () => {
    const noFolder = await serverLaunch(settings({ serverPath: 'nothing', configFile: 'ncc.toml' }), environment({ base: undefined }));
    assert.equal(!noFolder.ok && noFolder.setting, 'ncc.machine.configFile');
    const missing = await serverLaunch(settings({ serverPath: 'nothing' }), environment());
    assert.equal(!missing.ok && missing.setting, 'ncc.server.path');
    const outdated = await serverLaunch(settings({ serverPath: old }), environment());
    assert.match(!outdated.ok ? outdated.message : '', /is not an ncc with a language server/);
  });
});

describe('a server that exits as it starts', () => {
  test('is reported with the last lines it wrote on stderr, all of them logged', { skip: !posix }, async () => {
    const dying = path.join(scratch, 'dying-ncc');
    await fs.writeFile(
      dying,
      '#!/bin/sh\necho "loading ncc.toml" >&2\necho >&2\necho "error: the machine file m.toml:3: unknown key" >&2\nexit 1\n',
      { mode: 0o755 },
    );
    const stderr = new ServerStderr();
    const logged: string[] = [];
    const server = spawn(dying, ['lsp']);
    stderr.read(server.stderr, (line) => logged.push(line));
    // Asked as soon as the start fails: the lines still come.
    const lines = await stderr.lastLines(10_000);
    assert.deepEqual(logged, ['loading ncc.toml', '', 'error: the machine file m.toml:3: unknown key']);
    assert.equal(
      startFailure(dying, lines, new Error('write EPIPE')),
      `The ncc language server (${dying}) exited as it started: loading ncc.toml error: the machine file m.toml:3: unknown key`,
    );
  });

  test('keeps the last three lines, and waits for the rest no longer than asked', async () => {
    const input = new PassThrough();
    const stderr = new ServerStderr();
    stderr.read(input, () => undefined);
    input.write('one\ntwo\nthree\nfour\n');
    const started = Date.now();
    // The stream stays open, as that of a server that hangs would.
    assert.deepEqual(await stderr.lastLines(200), ['two', 'three', 'four']);
    assert.ok(Date.now() - started < 5_000);
    input.end();
  });

  test("without a word on stderr, the client's error says what happened", () => {
    assert.equal(
      startFailure('/opt/ncc', [], new Error('spawn /opt/ncc EACCES')),
      'The ncc language server (/opt/ncc) exited as it started without saying why: spawn /opt/ncc EACCES',
    );
  });
});
