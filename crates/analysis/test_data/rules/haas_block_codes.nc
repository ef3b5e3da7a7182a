O1001 (CODES OF THE CATALOGUE)
G50 S2000
G54 G00 X50. Z2.
G97 S800 M03
G01 G00 X40.
;   ^^^ same-group-codes
G54 G55 X30.
;   ^^^ same-group-codes
G96 G97 S100
;   ^^^ same-group-codes
G21 G20
;   ^^^ same-group-codes
G99 G98 F100.
;   ^^^ same-group-codes
G100 G101 X0
;    ^^^^ same-group-codes
G40 G41 X20.
;   ^^^ same-group-codes
G07 X20.
; @ unknown-g-code
G01 Z-5. F0.2 M08 M09
;                 ^^^ several-m-codes
M16
; @ unknown-m-code
M200
; @ unknown-m-code
G05 P1.
; @ undescribed-code
G60
; @ undescribed-code
G103 P1
; @ undescribed-code
G187 P3
; @ undescribed-code
G31 X10. F50.
; @ optional-function
M19
; @ optional-function
M51
; @ optional-function
M68
; @ optional-function
M121
; @ optional-function
M85
; @ optional-function
M88
; @ optional-function
M41
; @ restricted-code
M44
; @ restricted-code
M82
; @ restricted-code
; The default lathe has no C axis, so no live tooling.
G95 X0 Z-12. R3. F1.25
; @ live-tool-needed
M133 P1500
; @ live-tool-needed
G80
G00 G40 X60. Z100.
M30
