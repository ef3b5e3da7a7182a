-- Partprograms are `*.NCP` in any case; macrocycle files are `L` and digits,
-- without an extension (`L9001`). Lua patterns, matched against the whole
-- file name.
local names = { ".*%.[nN][cC][pP]", "L%d+" }

if vim.fn.has("nvim-0.8") == 1 then
  -- Through vim.filetype, so that vim.filetype.match() (used by pickers and
  -- previews) knows the type too.
  local pattern = {}
  for _, name in ipairs(names) do
    pattern[name] = "cnc8x6"
  end
  vim.filetype.add({ pattern = pattern })
else
  -- Neovim 0.7 (Debian 12) consults vim.filetype only when the user opted in
  -- to filetype.lua; autocommands work either way. The globs only narrow
  -- the files: `L1.bak` matches `L[0-9]*` too.
  vim.api.nvim_create_autocmd({ "BufRead", "BufNewFile" }, {
    pattern = { "*.[nN][cC][pP]", "L[0-9]*" },
    callback = function(args)
      local file = vim.fn.fnamemodify(args.match, ":t")
      for _, name in ipairs(names) do
        if file:match("^" .. name .. "$") then
          vim.cmd("setfiletype cnc8x6")
          return
        end
      end
    end,
  })
end
