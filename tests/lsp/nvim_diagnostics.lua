-- Neovim (headless, built-in LSP client) opens FERROC_MODEL with `ferroc lsp` attached
-- and prints the diagnostics it received, one per line: CODE LINE:COL SEVERITY.
-- Run by tests/lsp_clients.rs, which compares them with `ferroc check --format json`.
local ferroc = os.getenv("FERROC")
local model = os.getenv("FERROC_MODEL")
local out = os.getenv("FERROC_OUT")
vim.cmd("edit " .. vim.fn.fnameescape(model))
local buf = vim.api.nvim_get_current_buf()
local id = vim.lsp.start_client({
  name = "ferroc",
  cmd = { ferroc, "lsp" },
  root_dir = vim.fn.fnamemodify(model, ":h"),
})
vim.lsp.buf_attach_client(buf, id)
local got = vim.wait(60000, function()
  return #vim.diagnostic.get(buf) > 0
end, 50)
local lines = {}
if not got then
  table.insert(lines, "TIMEOUT")
end
for _, d in ipairs(vim.diagnostic.get(buf)) do
  local code = d.code
  if code == nil and d.user_data and d.user_data.lsp then
    code = d.user_data.lsp.code
  end
  table.insert(lines, string.format("%s %d:%d %d", tostring(code), d.lnum + 1, d.col + 1, d.severity))
end
vim.fn.writefile(lines, out)
vim.lsp.stop_client(id)
vim.wait(2000, function() return vim.lsp.client_is_stopped(id) end, 50)
vim.cmd("qa!")
