// Starts `ferroc lsp` for XML and .finroc files (docs/editors.md). Plain JavaScript: no
// build step between the repository and the .vsix.
const vscode = require("vscode");
const { LanguageClient } = require("vscode-languageclient/node");

let client;

function activate(context) {
  const config = vscode.workspace.getConfiguration("ferroc");
  const args = ["lsp"];
  for (const dir of config.get("libPath", [])) {
    args.push("--lib-path", dir);
  }
  const server = { command: config.get("path", "ferroc"), args };
  client = new LanguageClient(
    "ferroc",
    "ferroc",
    { run: server, debug: server },
    {
      documentSelector: [
        { scheme: "file", language: "xml" },
        { scheme: "file", pattern: "**/*.finroc" },
      ],
      synchronize: {
        fileEvents: vscode.workspace.createFileSystemWatcher("**/*.{xml,finroc,yaml}"),
      },
    }
  );
  context.subscriptions.push(client);
  return client.start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
