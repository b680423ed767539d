// urdftool for VS Code: starts `urdftool lsp` and tells it whether the workspace is trusted
// (VS Code's workspace trust, as initializationOptions.trusted); restarts it when trust is
// granted. Settings under "urdftool" are sent at start and on change.
const vscode = require('vscode');
const { LanguageClient } = require('vscode-languageclient/node');

let client;

function settings() {
  const config = vscode.workspace.getConfiguration('urdftool');
  const out = {};
  for (const key of ['packages', 'args', 'select', 'ignore', 'allowEnv']) {
    out[key] = config.get(key);
  }
  return out;
}

async function start() {
  const command = vscode.workspace.getConfiguration('urdftool').get('path') || 'urdftool';
  client = new LanguageClient('urdftool', 'urdftool', { command, args: ['lsp'] }, {
    documentSelector: [
      { scheme: 'file', pattern: '**/*.{urdf,xacro,sdf}' },
      // the YAML files a xacro loads (xacro.load_yaml): an unsaved edit is checked through
      // the xacro; a YAML file no check reads costs the server nothing
      { scheme: 'file', pattern: '**/*.{yaml,yml}' },
    ],
    initializationOptions: { trusted: vscode.workspace.isTrusted, ...settings() },
    synchronize: { configurationSection: 'urdftool' },
  });
  await client.start();
}

async function activate(context) {
  await start();
  context.subscriptions.push(vscode.workspace.onDidGrantWorkspaceTrust(async () => {
    await client.stop();
    await start();
  }));
}

async function deactivate() {
  if (client) {
    await client.stop();
  }
}

module.exports = { activate, deactivate };
