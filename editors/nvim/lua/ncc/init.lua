-- Starts the ncc language server for CNC programs. Works on Neovim 0.7
-- (Debian 12) and later, without nvim-lspconfig.

local M = {}

-- One filetype per control, named as ncc names its dialects. The server
-- picks each file's dialect itself, from its name and its project's
-- ncc.toml.
local filetypes = { "cnc8x6", "haas-lathe", "sinumerik" }

local uv = vim.uv or vim.loop

local option_names = { "cmd", "config_file", "log_level", "cycle_time_hints", "capabilities", "on_attach" }

-- The project root: the nearest directory that holds either marker.
local root_markers = { "ncc.toml", ".git" }

-- Written out because vim.fs.root needs Neovim 0.10. Without a marker the
-- file's own directory is the root.
local function root_dir(bufnr)
  local name = vim.api.nvim_buf_get_name(bufnr)
  local start = name == "" and vim.fn.getcwd() or vim.fn.fnamemodify(name, ":p:h")
  local dir = start
  while true do
    for _, marker in ipairs(root_markers) do
      if uv.fs_stat(dir .. "/" .. marker) then
        return dir
      end
    end
    local parent = vim.fn.fnamemodify(dir, ":h")
    if parent == dir then
      return start
    end
    dir = parent
  end
end

-- The predicted cycle time: inlay hints (Neovim 0.10 and later, which
-- also refresh them when the server asks) and the program's total as a
-- code lens, fetched again when the buffer is entered or left, and when
-- typing pauses.
local function show_cycle_time(bufnr)
  if vim.lsp.inlay_hint and vim.lsp.inlay_hint.enable then
    pcall(vim.lsp.inlay_hint.enable, true, { bufnr = bufnr })
  end
  local refresh = function()
    pcall(vim.lsp.codelens.refresh, { bufnr = bufnr })
  end
  vim.api.nvim_create_autocmd({ "BufEnter", "InsertLeave", "CursorHold" }, {
    group = vim.api.nvim_create_augroup("ncc_codelens_" .. bufnr, { clear = true }),
    buffer = bufnr,
    callback = refresh,
  })
  refresh()
end

local function client_config(opts, bufnr)
  local cmd = vim.deepcopy(opts.cmd)
  if opts.log_level then
    vim.list_extend(cmd, { "--log-level", opts.log_level })
  end
  local init_options = { cycleTime = { inlayHints = opts.cycle_time_hints } }
  if opts.config_file then
    init_options.configFile = vim.fn.fnamemodify(vim.fn.expand(opts.config_file), ":p")
  end
  return {
    name = "ncc",
    cmd = cmd,
    root_dir = root_dir(bufnr),
    init_options = init_options,
    capabilities = opts.capabilities,
    on_attach = function(client, attached)
      if opts.cycle_time_hints ~= "off" then
        show_cycle_time(attached)
      end
      if opts.on_attach then
        opts.on_attach(client, attached)
      end
    end,
  }
end

-- Client ids by root directory, for Neovim 0.7, which has no vim.lsp.start
-- to reuse a running server.
local clients = {}

local function start(config, bufnr)
  if vim.lsp.start then
    vim.lsp.start(config, { bufnr = bufnr })
    return
  end
  local id = clients[config.root_dir]
  local client = id and vim.lsp.get_client_by_id(id)
  if not client or client.is_stopped() then
    id = vim.lsp.start_client(config)
    clients[config.root_dir] = id
  end
  if id then
    vim.lsp.buf_attach_client(bufnr, id)
  end
end

--- Starts (or reuses) the server for every buffer of filetype `cnc8x6`,
--- `haas-lathe` or `sinumerik`: one server per project root.
---
--- Options, all optional:
--- - cmd: the server command, default `{ "ncc", "lsp" }`.
--- - config_file: the machine configuration for every program, instead of
---   the `ncc.toml` found above each one.
--- - log_level: the server's log level ("error", "warn", "info", "debug" or
---   "trace"). The server logs to stderr, which Neovim copies into its LSP
---   log, `vim.lsp.get_log_path()`.
--- - cycle_time_hints: "perBlock" (default), "cumulative" or "off": the
---   predicted time of each block, or the time at its end, as inlay hints.
--- - capabilities, on_attach: passed to the client as they are.
function M.setup(opts)
  opts = opts or {}
  for key in pairs(opts) do
    if not vim.tbl_contains(option_names, key) then
      error(
        ("ncc.setup: unknown option %q (known: %s)"):format(key, table.concat(option_names, ", ")),
        2
      )
    end
  end
  opts = vim.tbl_extend("keep", opts, { cmd = { "ncc", "lsp" }, cycle_time_hints = "perBlock" })

  vim.api.nvim_create_autocmd("FileType", {
    group = vim.api.nvim_create_augroup("ncc", { clear = true }),
    pattern = filetypes,
    callback = function(args)
      -- Help, terminal and scratch buffers are not files the server can read.
      if vim.bo[args.buf].buftype ~= "" then
        return
      end
      -- The server reads a buffer without a file name as CNC8x6, whatever
      -- its filetype.
      if args.match ~= "cnc8x6" and vim.api.nvim_buf_get_name(args.buf) == "" then
        return
      end
      start(client_config(opts, args.buf), args.buf)
    end,
  })
end

return M
