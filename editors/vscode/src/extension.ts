// The extension: starts `ncc lsp` for CNC programs and shows its state.

import * as os from 'node:os';
import * as vscode from 'vscode';
import {
  CloseAction,
  ErrorAction,
  type ErrorHandler,
  ExecuteCommandRequest,
  LanguageClient,
  type LanguageClientOptions,
  type ServerOptions,
  State,
} from 'vscode-languageclient/node';
import { DOCUMENT_SELECTOR, TOOLPATH_LANGUAGES } from './documents';
import { type Environment, type Launch, readSettings, ServerStderr, serverLaunch, startFailure } from './server';
import { type PlotView, PLOT_COMMAND, plotArguments } from './toolpath';
import { ToolpathViews } from './toolpathView';

/** How long a server that exited at start may take to finish its stderr. */
const STDERR_WAIT_MS = 2_000;

let server: Server | undefined;

export function activate(context: vscode.ExtensionContext): Promise<void> {
  const output = vscode.window.createOutputChannel('ncc', { log: true });
  const views = new ToolpathViews(context.extensionUri, (uri, view) =>
    server ? server.plot(uri, view) : Promise.reject(new Error('The ncc language server is not running.')),
  );
  server = new Server(output, () => views.refresh());
  context.subscriptions.push(
    output,
    server,
    views,
    vscode.commands.registerCommand('ncc.restartServer', () => server?.restart()),
    vscode.commands.registerCommand('ncc.showOutput', () => output.show(true)),
    vscode.commands.registerCommand('ncc.showToolpath', (resource?: unknown) => showToolpath(views, resource)),
    vscode.workspace.onDidChangeConfiguration((event) => {
      // The trace setting is read by the language client itself.
      if (event.affectsConfiguration('ncc.server') || event.affectsConfiguration('ncc.machine')) {
        void server?.restart();
      }
    }),
  );
  return server.restart();
}

export function deactivate(): Promise<void> | undefined {
  return server?.stop();
}

/**
 * `ncc.showToolpath`: the view of the document the editor title menu names
 * (`resource`), or of the active editor's.
 */
async function showToolpath(views: ToolpathViews, resource: unknown): Promise<void> {
  const active = vscode.window.activeTextEditor;
  let document = active?.document;
  let column = active?.viewColumn;
  if (resource instanceof vscode.Uri && resource.toString() !== document?.uri.toString()) {
    const shown = vscode.window.visibleTextEditors.find((e) => e.document.uri.toString() === resource.toString());
    document = shown?.document ?? (await vscode.workspace.openTextDocument(resource));
    column = shown?.viewColumn;
  }
  if (document === undefined || !(TOOLPATH_LANGUAGES as readonly string[]).includes(document.languageId)) {
    void vscode.window.showWarningMessage('ncc: the toolpath is drawn for CNC8x6 and Haas lathe programs; open one first.');
    return;
  }
  views.show(document, column);
}

type Status =
  | { state: 'starting' }
  | { state: 'running'; launch: Launch }
  | { state: 'stopped' }
  | { state: 'error'; message: string };

/** One language client at a time, and the status bar item that shows it. */
class Server implements vscode.Disposable {
  private client: LanguageClient | undefined;
  private readonly item: vscode.StatusBarItem;
  /** Set while the extension itself stops the client, so that the stop is not shown as a failure. */
  private stopping = false;
  private restarting: Promise<void> = Promise.resolve();

  constructor(
    private readonly output: vscode.LogOutputChannel,
    /** Called each time a server is running. */
    private readonly onRunning: () => void,
  ) {
    this.item = vscode.window.createStatusBarItem('ncc.status', vscode.StatusBarAlignment.Left);
    this.item.name = 'ncc';
    this.item.command = 'ncc.showOutput';
    this.show({ state: 'stopped' });
    this.item.show();
  }

  private async start(): Promise<void> {
    this.show({ state: 'starting' });
    const settings = readSettings((key) => vscode.workspace.getConfiguration('ncc').get(key));
    const launch = await serverLaunch(settings, environment());
    if (!launch.ok) {
      this.fail(launch.message);
      const open = 'Open Setting';
      // Not awaited: a notification can stay open for as long as the user likes.
      void vscode.window.showErrorMessage(launch.message, open).then((choice) => {
        if (choice === open) {
          void vscode.commands.executeCommand('workbench.action.openSettings', launch.setting);
        }
      });
      return;
    }
    const { command, args, initializationOptions } = launch.value;
    this.output.info(`Starting ${launch.value.version}: ${command} ${args.join(' ')}`);
    const stderr = new ServerStderr();
    // Until the server has answered `initialize`, its failures are this
    // class's to report (with what it wrote on stderr), not restarted.
    let started = false;
    let afterStart: ErrorHandler | undefined;
    const client = new StartReportingClient(
      () => started,
      { command, args },
      {
        documentSelector: DOCUMENT_SELECTOR,
        initializationOptions,
        // `ncc.cycleTime` changes reach the running server as
        // workspace/didChangeConfiguration.
        synchronize: { configurationSection: 'ncc' },
        outputChannel: this.output,
        stdioOptions: {
          // The protocol's stream, which the client reads itself.
          stdout: () => undefined,
          stderr: (input, output) => stderr.read(input, (line) => output.error(line)),
        },
        initializationFailedHandler: () => false,
        errorHandler: {
          error: (error, message, count) =>
            started && afterStart
              ? afterStart.error(error, message, count)
              : { action: ErrorAction.Shutdown, handled: true },
          closed: () => (started && afterStart ? afterStart.closed() : { action: CloseAction.DoNotRestart, handled: true }),
        },
      },
    );
    afterStart = client.createDefaultErrorHandler();
    client.onDidChangeState(({ newState }) => {
      switch (newState) {
        case State.Starting:
          this.show({ state: 'starting' });
          break;
        case State.Running:
          started = true;
          this.show({ state: 'running', launch: launch.value });
          this.onRunning();
          break;
        case State.Stopped:
          if (started && !this.stopping) {
            // The client gave up restarting a server that kept exiting.
            this.fail(`${command} stopped unexpectedly.`);
          }
          break;
        case State.StartFailed:
          // Reported where `start` fails.
          break;
      }
    });
    this.client = client;
    try {
      await client.start();
    } catch (error) {
      const message = startFailure(command, await stderr.lastLines(STDERR_WAIT_MS), error);
      this.fail(message);
      const log = 'Show Log';
      void vscode.window.showErrorMessage(message, log).then((choice) => {
        if (choice === log) {
          this.output.show(true);
        }
      });
    }
  }

  async stop(): Promise<void> {
    const client = this.client;
    this.client = undefined;
    // A client whose start failed has no server left to stop.
    if (client === undefined || !client.isRunning()) {
      this.show({ state: 'stopped' });
      return;
    }
    this.stopping = true;
    try {
      await client.dispose();
    } catch (error) {
      this.output.warn(`Stopping the server: ${error instanceof Error ? error.message : String(error)}`);
    } finally {
      this.stopping = false;
      this.show({ state: 'stopped' });
    }
  }

  /**
   * The picture of the open document at `uri`, drawn by the server from its
   * current text (`ncc.plot`), a lathe's in `view` (else the server's
   * default). Rejects with the server's error, whose `data` may hold the
   * picture of a run that stopped.
   */
  async plot(uri: string, view: PlotView | undefined): Promise<unknown> {
    // A restart in progress brings a client to ask.
    await this.restarting;
    const client = this.client;
    if (client === undefined || !client.isRunning()) {
      throw new Error('The ncc language server is not running.');
    }
    return client.sendRequest(ExecuteCommandRequest.type, {
      command: PLOT_COMMAND,
      arguments: plotArguments(uri, view),
    });
  }

  /** Stops the server if it runs, and starts it. */
  restart(): Promise<void> {
    // Restarts run one after another, however fast settings change, and a
    // failed one does not hold up the next.
    const next = this.restarting.then(async () => {
      await this.stop();
      await this.start();
    });
    this.restarting = next.catch(() => undefined);
    return next;
  }

  dispose(): void {
    void this.stop();
    this.item.dispose();
  }

  private fail(message: string): void {
    this.output.error(message);
    this.show({ state: 'error', message });
  }

  private show(status: Status): void {
    const tooltip = new vscode.MarkdownString('', true);
    tooltip.isTrusted = { enabledCommands: ['ncc.restartServer', 'ncc.showOutput'] };
    this.item.backgroundColor = undefined;
    switch (status.state) {
      case 'starting':
        this.item.text = '$(sync~spin) ncc';
        tooltip.appendText('The ncc language server is starting.');
        break;
      case 'running': {
        this.item.text = '$(check) ncc';
        tooltip.appendText(`${status.launch.version} is running:`).appendCodeblock(
          [status.launch.command, ...status.launch.args].join(' '),
          'text',
        );
        break;
      }
      case 'stopped':
        this.item.text = '$(circle-slash) ncc';
        tooltip.appendText('The ncc language server is stopped.');
        break;
      case 'error':
        this.item.text = '$(error) ncc';
        this.item.backgroundColor = new vscode.ThemeColor('statusBarItem.errorBackground');
        tooltip.appendText(status.message);
        break;
    }
    tooltip.appendMarkdown('\n\n[Restart](command:ncc.restartServer) · [Show log](command:ncc.showOutput)');
    this.item.tooltip = tooltip;
  }
}

/**
 * A language client that, until its server has answered `initialize`, logs
 * its errors without a notification of its own: the extension reports a
 * failed start itself, with the server's reason and a button to the log, and
 * a second notification (the client's "couldn't create connection") would
 * cover it.
 */
class StartReportingClient extends LanguageClient {
  constructor(
    private readonly started: () => boolean,
    server: ServerOptions,
    options: LanguageClientOptions,
  ) {
    super('ncc', 'ncc', server, options);
  }

  override error(message: string, data?: unknown, showNotification: boolean | 'force' = true): void {
    super.error(message, data, this.started() ? showNotification : false);
  }
}

function environment(): Environment {
  return {
    base: vscode.workspace.workspaceFolders?.[0]?.uri.fsPath,
    home: os.homedir(),
    env: process.env,
    platform: process.platform,
  };
}
