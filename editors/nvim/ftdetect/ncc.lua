-- One filetype per control, named as ncc names its dialects, for the file
-- names ncc maps to each by default: CNC8x6 partprograms `*.NCP` and
-- macrocycle files `L` and digits without an extension (`L9001`), Sinumerik
-- `*.MPF` and `*.SPF`, Haas lathe `*.nc` and `*.tap`; extensions in any
-- case. Besides, Haas program files named `O` and their number, without an
-- extension (`O01234`), as the control names them. Lua patterns, matched
-- against the whole file name.
local names = {
  { ".*%.[nN][cC][pP]", "cnc8x6" },
  { "L%d+", "cnc8x6" },
  { ".*%.[mM][pP][fF]", "sinumerik" },
  { ".*%.[sS][pP][fF]", "sinumerik" },
  { ".*%.[nN][cC]", "haas-lathe" },
  { ".*%.[tT][aA][pP]", "haas-lathe" },
  { "O%d+", "haas-lathe" },
}

if vim.fn.has("nvim-0.8") == 1 then
  -- Through vim.filetype, so that vim.filetype.match() (used by pickers and
  -- previews) knows the types too.
  local pattern = {}
  for _, name in ipairs(names) do
    pattern[name[1]] = name[2]
  end
  vim.filetype.add({ pattern = pattern })
else
  -- Neovim 0.7 (Debian 12) consults vim.filetype only when the user opted in
  -- to filetype.lua; autocommands work either way. The globs only narrow
  -- the files: `L1.bak` matches `L[0-9]*` too.
  vim.api.nvim_create_autocmd({ "BufRead", "BufNewFile" }, {
    pattern = {
      "*.[nN][cC][pP]",
      "L[0-9]*",
      "*.[mM][pP][fF]",
      "*.[sS][pP][fF]",
      "*.[nN][cC]",
      "*.[tT][aA][pP]",
      "O[0-9]*",
    },
    callback = function(args)
      local file = vim.fn.fnamemodify(args.match, ":t")
      for _, name in ipairs(names) do
        if file:match("^" .. name[1] .. "$") then
          vim.cmd("setfiletype " .. name[2])
          return
        end
      end
    end,
  })
end
