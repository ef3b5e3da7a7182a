" Filetype plugin for Siemens Sinumerik programs

if exists('b:did_ftplugin')
  finish
endif
let b:did_ftplugin = 1

" Comment commands write the semicolon the control reads as a comment.
setlocal commentstring=;%s
let b:undo_ftplugin = 'setlocal commentstring<'
