// How the extension starts `ncc lsp`: reading the settings, finding the
// binary and building its command line and initialization options. This
// module does not import `vscode`, so the tests run it in plain node.

import { execFile } from 'node:child_process';
import { constants, promises as fs } from 'node:fs';
import * as path from 'node:path';
import * as readline from 'node:readline';
import type { Readable } from 'node:stream';

const LOG_LEVELS = ['error', 'warn', 'info', 'debug', 'trace'] as const;
export type LogLevel = (typeof LOG_LEVELS)[number];

/** What `package.json` declares as the default of `ncc.server.logLevel`. */
const DEFAULT_LOG_LEVEL: LogLevel = 'warn';

const CYCLE_TIME_HINTS = ['perBlock', 'cumulative', 'off'] as const;
export type CycleTimeHints = (typeof CYCLE_TIME_HINTS)[number];

/** What `package.json` declares as the default of `ncc.cycleTime.inlayHints`. */
const DEFAULT_CYCLE_TIME_HINTS: CycleTimeHints = 'perBlock';

/** The settings that decide how the server starts. */
export interface Settings {
  /** `ncc.server.path`; empty: `ncc` on PATH. */
  serverPath: string;
  /** `ncc.server.logLevel`. */
  logLevel: LogLevel;
  /** `ncc.machine.configFile`; empty: each program's own `ncc.toml`. */
  configFile: string;
  /** `ncc.cycleTime.inlayHints`. */
  cycleTimeHints: CycleTimeHints;
}

/**
 * What the server reads from `initialize`'s `initializationOptions`. Later
 * changes of `cycleTime` reach it as `workspace/didChangeConfiguration`.
 */
export interface InitializationOptions {
  configFile?: string;
  cycleTime: { inlayHints: CycleTimeHints };
}

/** A server command line and its initialization options. */
export interface Launch {
  command: string;
  args: string[];
  initializationOptions: InitializationOptions;
  /** What `ncc lsp --version` printed, e.g. `ncc 0.1.0`. */
  version: string;
}

/** Where relative paths and `ncc` on PATH are looked up. */
export interface Environment {
  /** The first workspace folder, against which relative paths resolve. */
  base: string | undefined;
  home: string;
  env: NodeJS.ProcessEnv;
  platform: NodeJS.Platform;
}

/** A value, or why there is none and which setting to change. */
export type Result<T> = { ok: true; value: T } | { ok: false; message: string; setting: Setting };

export type Setting = 'ncc.server.path' | 'ncc.machine.configFile';

/**
 * Reads the settings through `get`, which takes a key below `ncc.` (the
 * `get` of `workspace.getConfiguration('ncc')`). A value of the wrong type,
 * which only a hand-edited settings.json can hold, counts as unset.
 */
export function readSettings(get: (key: string) => unknown): Settings {
  const text = (key: string): string => {
    const value = get(key);
    return typeof value === 'string' ? value.trim() : '';
  };
  const level = text('server.logLevel');
  const hints = text('cycleTime.inlayHints');
  return {
    serverPath: text('server.path'),
    logLevel: isLogLevel(level) ? level : DEFAULT_LOG_LEVEL,
    configFile: text('machine.configFile'),
    cycleTimeHints: (CYCLE_TIME_HINTS as readonly string[]).includes(hints)
      ? (hints as CycleTimeHints)
      : DEFAULT_CYCLE_TIME_HINTS,
  };
}

function isLogLevel(value: string): value is LogLevel {
  return (LOG_LEVELS as readonly string[]).includes(value);
}

/**
 * The absolute path a path setting names: `~` is the home directory, and a
 * relative path starts at the first workspace folder. Undefined for a
 * relative path when no folder is open.
 */
export function resolveSettingPath(value: string, environment: Environment): string | undefined {
  if (value === '~' || value.startsWith('~/') || value.startsWith('~\\')) {
    return path.join(environment.home, value.slice(1));
  }
  if (path.isAbsolute(value)) {
    return path.normalize(value);
  }
  return environment.base === undefined ? undefined : path.resolve(environment.base, value);
}

/** The `ncc` binary: the one `ncc.server.path` names, or the first on PATH. */
export async function findServer(settings: Settings, environment: Environment): Promise<Result<string>> {
  if (settings.serverPath !== '') {
    return configuredServer(settings.serverPath, environment);
  }
  const dirs = (environment.env['PATH'] ?? '').split(path.delimiter).filter((dir) => dir !== '');
  for (const dir of dirs) {
    for (const name of executableNames('ncc', environment)) {
      const candidate = path.join(dir, name);
      if ((await executable(candidate, environment.platform)) === 'yes') {
        return { ok: true, value: candidate };
      }
    }
  }
  return {
    ok: false,
    setting: 'ncc.server.path',
    message:
      'ncc was not found on the PATH that VS Code runs with. Install it with ' +
      '"cargo install --path crates/lsp" in the ncc repository, or set ncc.server.path to the binary.',
  };
}

async function configuredServer(value: string, environment: Environment): Promise<Result<string>> {
  const setting = 'ncc.server.path';
  const file = resolveSettingPath(value, environment);
  if (file === undefined) {
    return { ok: false, setting, message: noFolder(setting, value) };
  }
  const state = await executable(file, environment.platform);
  if (state === 'yes') {
    return { ok: true, value: file };
  }
  const problem = { missing: 'does not exist', 'not a file': 'is not a file', 'not executable': 'is not executable' }[state];
  return { ok: false, setting, message: `${setting} names ${file}, which ${problem}.` };
}

function noFolder(setting: Setting, value: string): string {
  return `${setting} is the relative path ${value}, but no folder is open to resolve it against.`;
}

/** The file names a command may have: on Windows, one for each of PATHEXT's extensions. */
function executableNames(command: string, environment: Environment): string[] {
  if (environment.platform !== 'win32') {
    return [command];
  }
  const extensions = (environment.env['PATHEXT'] ?? '.COM;.EXE;.BAT;.CMD').split(';').filter((ext) => ext !== '');
  return extensions.map((ext) => command + ext);
}

type Executable = 'yes' | 'missing' | 'not a file' | 'not executable';

async function executable(file: string, platform: NodeJS.Platform): Promise<Executable> {
  let stat;
  try {
    stat = await fs.stat(file);
  } catch {
    return 'missing';
  }
  if (!stat.isFile()) {
    return 'not a file';
  }
  if (platform === 'win32') {
    return 'yes';
  }
  try {
    await fs.access(file, constants.X_OK);
    return 'yes';
  } catch {
    return 'not executable';
  }
}

/** The options the server reads at `initialize`. */
export function initializationOptions(settings: Settings, environment: Environment): Result<InitializationOptions> {
  const cycleTime = { inlayHints: settings.cycleTimeHints };
  if (settings.configFile === '') {
    return { ok: true, value: { cycleTime } };
  }
  const configFile = resolveSettingPath(settings.configFile, environment);
  if (configFile === undefined) {
    const setting = 'ncc.machine.configFile';
    return { ok: false, setting, message: noFolder(setting, settings.configFile) };
  }
  return { ok: true, value: { configFile, cycleTime } };
}

/** How long `ncc lsp --version` may take: a cold start from a slow disk. */
const VERSION_TIMEOUT_MS = 10_000;

/**
 * What `ncc lsp --version` prints. It fails for a binary that is not ncc or
 * that was built before ncc had a language server, which the user can fix
 * in `ncc.server.path`.
 */
export function serverVersion(command: string): Promise<Result<string>> {
  return new Promise((resolve) => {
    execFile(command, ['lsp', '--version'], { timeout: VERSION_TIMEOUT_MS }, (error, stdout, stderr) => {
      const version = stdout.trim();
      if (error === null && version.startsWith('ncc ')) {
        resolve({ ok: true, value: version });
        return;
      }
      const said = (stderr.trim() || version || (error?.message ?? '')).split('\n')[0];
      resolve({
        ok: false,
        setting: 'ncc.server.path',
        message:
          `${command} is not an ncc with a language server: "ncc lsp --version" answered "${said}". ` +
          'Install a current ncc with "cargo install --path crates/lsp", or set ncc.server.path to one.',
      });
    });
  });
}

/** Everything needed to start the server, or why it cannot start. */
export async function serverLaunch(settings: Settings, environment: Environment): Promise<Result<Launch>> {
  const options = initializationOptions(settings, environment);
  if (!options.ok) {
    return options;
  }
  const command = await findServer(settings, environment);
  if (!command.ok) {
    return command;
  }
  const version = await serverVersion(command.value);
  if (!version.ok) {
    return version;
  }
  return {
    ok: true,
    value: {
      command: command.value,
      args: ['lsp', '--log-level', settings.logLevel],
      initializationOptions: options.value,
      version: version.value,
    },
  };
}

/** How many of the server's last lines on stderr a failure quotes. */
const REASON_LINES = 3;

/**
 * A server's stderr: each line goes on to the log, and the last few are kept
 * to say why a server that exited as it started did so.
 */
export class ServerStderr {
  private readonly last: string[] = [];
  private ended: Promise<void> = Promise.resolve();

  /** Reads `input` line by line, handing each line to `log`. */
  read(input: Readable, log: (line: string) => void): void {
    const lines = readline.createInterface({ input, crlfDelay: Infinity, terminal: false, historySize: 0 });
    this.ended = new Promise((resolve) => lines.once('close', resolve));
    lines.on('line', (line) => {
      log(line);
      if (line.trim() !== '') {
        this.last.push(line.trim());
        this.last.splice(0, this.last.length - REASON_LINES);
      }
    });
  }

  /**
   * The last lines the server wrote, once its stderr has ended or `waitMs`
   * have passed: a process that has died may still have lines on the way.
   */
  async lastLines(waitMs: number): Promise<string[]> {
    let timer: NodeJS.Timeout | undefined;
    const timeout = new Promise<void>((resolve) => (timer = setTimeout(resolve, waitMs)));
    await Promise.race([this.ended, timeout]);
    clearTimeout(timer);
    return [...this.last];
  }
}

/**
 * What the user is told when the server exited before it answered
 * `initialize`: what it wrote last on stderr, or the client's error.
 */
export function startFailure(command: string, stderr: readonly string[], error: unknown): string {
  const server = `The ncc language server (${command}) exited as it started`;
  if (stderr.length > 0) {
    return `${server}: ${stderr.join(' ')}`;
  }
  return `${server} without saying why: ${error instanceof Error ? error.message : String(error)}`;
}
