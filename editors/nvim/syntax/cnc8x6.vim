" Vim syntax file
" Language: MEFI CNC8x6 partprograms (*.NCP, macrocycle files L<number>)
" Highlighting without the language server; its semantic tokens refine it.

if exists('b:current_syntax')
  finish
endif

" Lowercase addresses are mistakes the server reports; show them as written.
syntax case ignore

" Among matches that start at one place the last defined wins, so the
" coded words come after the plain number.
syntax match cnc8x6Number /[+-]\=\(\d\+\.\=\d*\|\.\d\+\)/
syntax match cnc8x6GCode /G\d\+/
syntax match cnc8x6MCode /M\d\+/
syntax match cnc8x6BlockNumber /N\d\+/
syntax match cnc8x6Parameter /R\d\+/
syntax match cnc8x6Operator /=/
syntax match cnc8x6BlockSkip /\//
syntax match cnc8x6Header /%\d*/
" The physical end: the control reads nothing after it.
syntax match cnc8x6End /\*/

" A comment runs to its closing quote or to the end of the line.
syntax match cnc8x6Comment /"[^"]*"\=/ contains=cnc8x6Ignore
syntax match cnc8x6Ignore /ncc:ignore/ contained

highlight default link cnc8x6Number Number
highlight default link cnc8x6GCode Statement
highlight default link cnc8x6MCode Function
highlight default link cnc8x6BlockNumber Label
highlight default link cnc8x6Parameter Identifier
highlight default link cnc8x6Operator Operator
highlight default link cnc8x6BlockSkip Special
highlight default link cnc8x6Header PreProc
highlight default link cnc8x6End PreProc
highlight default link cnc8x6Comment Comment
highlight default link cnc8x6Ignore SpecialComment

let b:current_syntax = 'cnc8x6'
