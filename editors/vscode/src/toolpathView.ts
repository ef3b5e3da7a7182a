// The toolpath view: a webview beside a document with the picture of
// `ncc plot`, drawn by the server from the document's current text. A click
// on a move selects its line; the line the cursor is on is highlighted. The
// logic lives in toolpath.ts; this file wires it to VS Code.

import { randomBytes } from 'node:crypto';
import * as path from 'node:path';
import * as vscode from 'vscode';
import {
  failureMessage,
  nonceOf,
  pageHtml,
  panelTitle,
  parseFromView,
  parsePlotted,
  plotMessage,
  RenderSchedule,
  type PlotView,
  type Reveal,
  revealTarget,
  sourceFiles,
  type ToView,
  VIEW_SCRIPT,
} from './toolpath';

/**
 * Asks the server for the picture of the document at `uri`, a lathe's in
 * `view` (else the server's default); rejects with the server's error.
 */
export type Plot = (uri: string, view: PlotView | undefined) => Promise<unknown>;

/** One view per document, opened by `ncc.showToolpath`. */
export class ToolpathViews implements vscode.Disposable {
  private readonly views = new Map<string, ToolpathView>();

  constructor(
    private readonly extensionUri: vscode.Uri,
    private readonly plot: Plot,
  ) {}

  /** Shows the view of `document`, opening it beside the editor in `column`. */
  show(document: vscode.TextDocument, column: vscode.ViewColumn | undefined): void {
    const key = document.uri.toString();
    const open = this.views.get(key);
    if (open) {
      open.reveal();
      return;
    }
    const view = new ToolpathView(document.uri, column, this.extensionUri, this.plot, () => this.views.delete(key));
    this.views.set(key, view);
  }

  /** Draws every view again (the server restarted). */
  refresh(): void {
    for (const view of this.views.values()) {
      view.refresh();
    }
  }

  dispose(): void {
    for (const view of [...this.views.values()]) {
      view.dispose();
    }
  }
}

class ToolpathView {
  private readonly key: string;
  private readonly panel: vscode.WebviewPanel;
  private readonly schedule: RenderSchedule;
  private readonly subscriptions: vscode.Disposable[] = [];
  private readonly name: string;
  /** What the page shows, sent again when the page is rebuilt (it was hidden). */
  private last: ToView | undefined;
  /** The other files the picture names: the only ones a click may open. */
  private files: ReadonlySet<string> = new Set();
  /** The lathe's view the page chose; until then the server's default. */
  private view: PlotView | undefined;
  private disposed = false;

  constructor(
    /** The plotted document's. */
    private readonly uri: vscode.Uri,
    /** The editor's column, where a click opens the document when no editor shows it. */
    private readonly column: vscode.ViewColumn | undefined,
    extensionUri: vscode.Uri,
    private readonly plot: Plot,
    private readonly onDispose: () => void,
  ) {
    this.key = uri.toString();
    this.name = path.basename(uri.path) || this.key;
    const scripts = vscode.Uri.joinPath(extensionUri, 'dist');
    this.panel = vscode.window.createWebviewPanel(
      'ncc.toolpath',
      panelTitle(this.name),
      { viewColumn: vscode.ViewColumn.Beside, preserveFocus: true },
      { enableScripts: true, localResourceRoots: [scripts] },
    );
    const webview = this.panel.webview;
    webview.html = pageHtml({
      nonce: nonceOf(randomBytes(16)),
      scriptUri: webview.asWebviewUri(vscode.Uri.joinPath(scripts, VIEW_SCRIPT)).toString(),
      title: panelTitle(this.name),
    });
    this.schedule = new RenderSchedule(() => this.render());
    this.subscriptions.push(
      this.panel.onDidDispose(() => this.dispose()),
      webview.onDidReceiveMessage((message: unknown) => this.receive(message)),
      vscode.workspace.onDidChangeTextDocument((event) => {
        if (this.isPlotted(event.document) && event.contentChanges.length > 0) {
          this.schedule.soon();
        }
      }),
      vscode.workspace.onDidSaveTextDocument((saved) => {
        if (this.isPlotted(saved)) {
          void this.schedule.now();
        }
      }),
      vscode.window.onDidChangeTextEditorSelection((event) => {
        if (this.isPlotted(event.textEditor.document)) {
          this.highlight(event.selections[0]?.active.line);
        }
      }),
    );
    void this.schedule.now();
  }

  reveal(): void {
    this.panel.reveal(undefined, true);
  }

  refresh(): void {
    void this.schedule.now();
  }

  /** By address: a document closed and opened again is another object. */
  private isPlotted(document: vscode.TextDocument): boolean {
    return document.uri.toString() === this.key;
  }

  dispose(): void {
    if (this.disposed) {
      return;
    }
    this.disposed = true;
    this.schedule.dispose();
    this.subscriptions.splice(0).forEach((subscription) => subscription.dispose());
    this.panel.dispose();
    this.onDispose();
  }

  private async render(): Promise<void> {
    let message: ToView;
    try {
      const plotted = parsePlotted(await this.plot(this.key, this.view));
      if (plotted === undefined) {
        throw new Error('The server answered ncc.plot without a picture.');
      }
      message = plotMessage(plotted);
      this.files = sourceFiles(plotted.svg);
      this.panel.title = panelTitle(this.name, plotted.totalTimeS);
    } catch (error) {
      const failed = failureMessage(error);
      message = failed;
      this.files = sourceFiles(failed.svg ?? '');
      this.panel.title = `${panelTitle(this.name)} · error`;
    }
    if (!this.disposed) {
      this.last = message;
      void this.panel.webview.postMessage(message);
    }
  }

  private receive(message: unknown): void {
    const parsed = parseFromView(message);
    if (parsed?.type === 'ready') {
      // A page rebuilt after it was hidden has nothing yet.
      if (this.last) {
        void this.panel.webview.postMessage(this.last);
      }
      const editor = vscode.window.visibleTextEditors.find((e) => this.isPlotted(e.document));
      this.highlight(editor?.selection.active.line);
    } else if (parsed?.type === 'reveal') {
      void this.revealLine(parsed);
    } else if (parsed?.type === 'view' && parsed.view !== this.view) {
      this.view = parsed.view;
      void this.schedule.now();
    }
  }

  /** Highlights the moves of `line` (from 0). */
  private highlight(line: number | undefined): void {
    void this.panel.webview.postMessage({ type: 'highlight', line: line === undefined ? null : line + 1 });
  }

  /** Selects the line a click means, in the editor that shows its file or a new one. */
  private async revealLine(reveal: Reveal): Promise<void> {
    try {
      const plotted = await vscode.workspace.openTextDocument(this.uri);
      const target = revealTarget(reveal, plotted.lineCount, this.files);
      if (target === undefined) {
        return;
      }
      const uri = target.file === undefined ? this.uri : vscode.Uri.file(target.file);
      const document = target.file === undefined ? plotted : await vscode.workspace.openTextDocument(uri);
      const shown = vscode.window.visibleTextEditors.find((e) => e.document.uri.toString() === uri.toString());
      const line = document.lineAt(Math.min(target.line, document.lineCount - 1)).range;
      const editor = await vscode.window.showTextDocument(document, {
        viewColumn: shown?.viewColumn ?? this.column ?? vscode.ViewColumn.One,
        selection: new vscode.Selection(line.start, line.end),
      });
      editor.revealRange(line, vscode.TextEditorRevealType.InCenterIfOutsideViewport);
    } catch (error) {
      void vscode.window.showErrorMessage(`ncc: ${error instanceof Error ? error.message : String(error)}`);
    }
  }
}
