" Filetype plugin for MEFI CNC8x6 partprograms

if exists('b:did_ftplugin')
  finish
endif
let b:did_ftplugin = 1

" A comment opens with `"` and may run to the end of the line.
setlocal commentstring=\"%s
let b:undo_ftplugin = 'setlocal commentstring<'
