" Vim syntax file
" Language: Haas lathe programs, classic control (*.nc, *.tap, program files O<number>)
" Highlighting without the language server; its semantic tokens refine it.

if exists('b:current_syntax')
  finish
endif

" Lower-case addresses are mistakes the server reports; show them as written.
syntax case ignore

" Among matches that start at one place the last defined wins: the words
" come after the plain number, the keywords after the letters.
syntax match haasLathePlainNumber /\(\d\+\.\=\d*\|\.\d\+\)/
syntax match haasLatheOperator /[-+*/=]/
" Right after an address letter, the sign belongs to the number.
syntax match haasLatheNumber /\(\a\s*\)\@<=[-+]\=\(\d\+\.\=\d*\|\.\d\+\)/
" Characters ncc's lexer does not know, and ones out of place.
syntax match haasLatheError /[^ \t0-9A-Za-z.+*/=#[\],%();-]\+/
syntax match haasLatheError /[%#)]/
syntax match haasLatheStray /[\],]/
syntax match haasLatheAxis /[xzuwycbhikjra]/
syntax match haasLatheAddress /[festpqld]/
" The control has no address V.
syntax match haasLatheError /v/
syntax match haasLatheCorner /,[cr]/
syntax match haasLatheGCode /g\s*\d\+\.\=\d*/
syntax match haasLatheMCode /m\s*\d\+/
" The macro call, program end, and the calls of and return from subprograms.
syntax match haasLatheFlow /g\s*0*65\([0-9.]\)\@!/
syntax match haasLatheFlow /m\s*0*\(2\|30\|9[789]\)\([0-9.]\)\@!/
syntax match haasLatheBlockNumber /n\s*\d*/
syntax match haasLatheProgramNumber /o\s*\d*/
syntax match haasLatheVariable /#\(\d\+\|\[\@=\)/
" The first thing in a block; a digit 1 to 9 right after it picks the switch.
syntax match haasLatheBlockSkip /^\s*\zs\/\([1-9]\([0-9.]\)\@!\)\=/
" A tape mark is alone on its line; elsewhere % is a mistake (above).
syntax match haasLatheTapeMark /^\s*%/

" An expression in brackets ends on its line; a letter in it that starts no
" keyword is a mistake.
syntax cluster haasLatheExpression contains=haasLathePlainNumber,haasLatheNumber,haasLatheOperator,haasLatheVariable,haasLatheBrackets,haasLatheComment,haasLatheLetter,haasLatheError,haasLatheConditional,haasLatheFunction,haasLatheOperatorWord
syntax region haasLatheBrackets matchgroup=haasLatheBracket start=/\[/ end=/\]/ end=/$/ oneline contains=@haasLatheExpression
syntax match haasLatheLetter /\a/ contained

" Keywords: upper case only and without a word boundary, as ncc's lexer
" reads them (GOTO5 is GOTO 5, G05 is G 05). The operators and functions
" are those of the catalogue (crates/catalog/data/haas-lathe/operations.toml).
syntax case match
syntax match haasLatheConditional /IF\|THEN/
syntax match haasLatheGoto /GOTO/ nextgroup=haasLatheTarget skipwhite
syntax match haasLatheTarget /\d\+/ contained
syntax match haasLatheRepeat /WHILE\|\(DO\|END\)\(\s*[1-3]\([0-9.]\)\@!\)\=/
syntax match haasLatheFunction /ROUND\|ATAN\|ASIN\|ACOS\|SQRT\|SIN\|COS\|TAN\|ABS\|FIX\|FUP/
syntax match haasLatheOperatorWord /EQ\|NE\|GT\|GE\|LT\|LE\|XOR\|AND\|OR\|MOD/
syntax case ignore

" A comment runs to its closing parenthesis or to the end of the line; the
" one right after the program number is the program's name.
syntax match haasLatheComment /([^)]*)\=/ contains=haasLatheIgnore
syntax match haasLatheComment /;.*/ contains=haasLatheIgnore
syntax match haasLatheProgramName /\(o\s*\d\+\s*\)\@<=([^)]*)\=/
syntax match haasLatheIgnore /ncc:ignore/ contained

highlight default link haasLathePlainNumber Number
highlight default link haasLatheNumber Number
highlight default link haasLatheOperator Operator
highlight default link haasLatheError Error
highlight default link haasLatheStray Error
highlight default link haasLatheAxis Type
highlight default link haasLatheAddress Special
highlight default link haasLatheCorner Special
highlight default link haasLatheGCode Statement
highlight default link haasLatheMCode Function
highlight default link haasLatheFlow Keyword
highlight default link haasLatheBlockNumber Label
highlight default link haasLatheProgramNumber PreProc
highlight default link haasLatheVariable Identifier
highlight default link haasLatheBlockSkip Special
highlight default link haasLatheTapeMark PreProc
highlight default link haasLatheBracket Delimiter
highlight default link haasLatheLetter Error
highlight default link haasLatheConditional Conditional
highlight default link haasLatheGoto Keyword
highlight default link haasLatheTarget Label
highlight default link haasLatheRepeat Repeat
highlight default link haasLatheFunction Function
highlight default link haasLatheOperatorWord Operator
highlight default link haasLatheComment Comment
highlight default link haasLatheProgramName Title
highlight default link haasLatheIgnore SpecialComment

let b:current_syntax = 'haas-lathe'
