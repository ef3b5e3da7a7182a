" Vim syntax file
" Language: Siemens Sinumerik programs (*.MPF, *.SPF)
" Highlighting without the language server; its semantic tokens refine it.
" A block is a line; names are case-insensitive. As in ncc's lexer, a letter
" followed by a letter or _ (or _ itself) starts a name, any other letter is
" an address.

if exists('b:current_syntax')
  finish
endif

syntax case ignore

" Among matches that start at one place the last defined wins; keywords win
" over matches.
syntax match sinumerikNumber /\(\d\+\.\=\d*\|\.\d\+\)\(ex[-+]\=\d\+\)\=/
syntax match sinumerikOperator /[-+*/=<>:]/
syntax match sinumerikOperator /==\|<>\|<=\|>=\|<</
syntax match sinumerikDelimiter /[()[\],]/
" Characters ncc's lexer does not know.
syntax match sinumerikError /[^ \t0-9A-Za-z_$.+*/=<>:;"'()[\],-]\+/
" A letter with its value, a sign or =: X10, X=R1+5, G0X10Y20.
syntax match sinumerikAxis /\([a-z_$]\)\@<![xyzabc]\ze\s*[-+0-9.=]/
syntax match sinumerikAxis /\([a-z_$]\)\@<![ijk]\ze\s*[-+0-9.=]/
syntax match sinumerikAddress /\([a-z_$]\)\@<![fstdhlp]\ze\s*[-+0-9.=]/
" Names of the program's own: variables, labels, subprograms.
syntax match sinumerikName /\([a-z_$]\)\@<!\([a-z][a-z_]\|_\)\w*/
" The addresses of more than one letter, before their =.
syntax match sinumerikAddress /\([a-z_$]\)\@<!\(adispos\|adis\|chf\|chr\|ctol\|lead\|otol\|rndm\|rnd\|tilt\|turn\|ap\|ar\|cr\|pl\|po\|pw\|rp\|sd\|xh\|yh\|zh\|[abc][2-5]\)\ze\s*=/
syntax match sinumerikGCode /\([a-z_$]\)\@<!g\d\+/
syntax match sinumerikMCode /\([a-z_$]\)\@<!m\d\+/
" Program end and the subprogram's return.
syntax match sinumerikFlow /\([a-z_$]\)\@<!m0*\(2\|30\|17\)\([0-9.]\)\@!/
syntax match sinumerikParameter /\([a-z_$]\)\@<!r\(\d\+\|\[\@=\)/
syntax match sinumerikBlockNumber /\([a-z_$]\)\@<!n\d\+/
syntax match sinumerikBlockNumber /^\s*\zs:\d\+/
syntax match sinumerikSystemVariable /\$\h\w*/
" A subprogram called by name with arguments, and the cycles.
syntax match sinumerikCall /\([a-z_$]\)\@<!\([a-z][a-z_]\|_\)\w*\ze\s*(/
syntax match sinumerikCycle /\<\(cycle\|pocket\|slot\|holes\)\d\+\>/
" The first things of a block: skip, number, label.
syntax match sinumerikBlockSkip /^\s*\zs\/\d\=/
syntax match sinumerikLabel /^\s*\(\/\d\=\s*\)\=\(\(n\d\+\|:\d\+\)\s*\)\=\zs\([a-z][a-z_]\|_\)\w*:\(=\)\@!/
syntax match sinumerikHeader /^\s*%\S*/

" The keywords, functions and word codes of ncc's catalogue
" (crates/catalog/data/sinumerik/).
syntax keyword sinumerikStatement IF ELSE ENDIF WHILE ENDWHILE FOR TO ENDFOR LOOP ENDLOOP REPEAT UNTIL
syntax keyword sinumerikStatement CASE OF DEFAULT GOTOF GOTOB GOTOC GOTOS GOTO RET PCALL MCALL CALL BLOCK
syntax keyword sinumerikStatement WHENEVER WHEN FROM EVERY DO
syntax keyword sinumerikType REAL INT BOOL CHAR STRING AXIS FRAME
syntax keyword sinumerikDeclaration DEFINE DEF PROC VAR EXTERN SAVE DISPLOF SBLOF AS NCK CHAN
syntax keyword sinumerikConstant TRUE FALSE
syntax keyword sinumerikOperatorWord B_NOT B_AND B_XOR B_OR NOT AND XOR OR DIV MOD
syntax keyword sinumerikKeyword _OFF _FINISH _SEMIFIN _ROUGH STOPRE TRAORI TRAFOOF TCARR ID IDS
syntax keyword sinumerikWordCode CIP ASPLINE BSPLINE CSPLINE POLY CT TRANS ROT SCALE MIRROR ATRANS AROT
syntax keyword sinumerikWordCode ASCALE AMIRROR STARTFIFO STOPFIFO FIFOCTRL SUPA NORM KONT KONTT KONTC
syntax keyword sinumerikWordCode BNAT BTAN BAUTO ENAT ETAN EAUTO BRISK SOFT DRIVE CUT2D CUT2DF CUT3DC
syntax keyword sinumerikWordCode CUT3DF CUT3DFS CUT3DFF CUT3DCC FFWOF FFWON ORIWKS ORIMKS COMPOF COMPON
syntax keyword sinumerikWordCode COMPCURV COMPCAD SPATH UPATH ORIEULER ORIRPY ORIVECT ORIAXES ORICURVE
syntax keyword sinumerikWordCode PAROTOF PAROT TOROTOF TOROT DYNNORM DYNPOS DYNROUGH DYNSEMIFIN DYNFINISH
syntax keyword sinumerikWordCode ORISOF ORISON
syntax keyword sinumerikFunction SIN COS TAN ASIN ACOS ATAN2 SQRT POT ABS TRUNC ROUND ROUNDUP LN EXP
syntax keyword sinumerikFunction MINVAL MAXVAL BOUND AC IC STRLEN INDEX RINDEX SUBSTR NUMBER ISNUMBER
syntax keyword sinumerikFunction AXSTRING AXNAME TOUPPER TOLOWER SET REP WRITE DELETE READ ISFILE MSG
syntax keyword sinumerikFunction GROUP_BEGIN GROUP_END WORKPIECE GETSELT GETEXET SPLINEPATH CONTPRON EXECUTE

" A string and a comment end with their line.
syntax region sinumerikString start=/"/ end=/"/ end=/$/ oneline
syntax match sinumerikString /'[^']*'\=/
syntax match sinumerikComment /;.*/ contains=sinumerikIgnore
syntax match sinumerikIgnore /ncc:ignore/ contained

highlight default link sinumerikNumber Number
highlight default link sinumerikOperator Operator
highlight default link sinumerikDelimiter Delimiter
highlight default link sinumerikError Error
highlight default link sinumerikAxis Type
highlight default link sinumerikAddress Special
highlight default link sinumerikGCode Statement
highlight default link sinumerikMCode Function
highlight default link sinumerikFlow Keyword
highlight default link sinumerikParameter Identifier
highlight default link sinumerikBlockNumber Label
highlight default link sinumerikSystemVariable Identifier
highlight default link sinumerikCall Function
highlight default link sinumerikCycle Function
highlight default link sinumerikBlockSkip Special
highlight default link sinumerikLabel Label
highlight default link sinumerikHeader PreProc
highlight default link sinumerikStatement Statement
highlight default link sinumerikType Type
highlight default link sinumerikDeclaration StorageClass
highlight default link sinumerikConstant Constant
highlight default link sinumerikOperatorWord Operator
highlight default link sinumerikKeyword Keyword
highlight default link sinumerikWordCode Statement
highlight default link sinumerikFunction Function
highlight default link sinumerikString String
highlight default link sinumerikComment Comment
highlight default link sinumerikIgnore SpecialComment

let b:current_syntax = 'sinumerik'
