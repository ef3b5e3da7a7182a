O1005 (CONTOUR CYCLES AND THEIR START POINT)
G50 S2000
G54 G00 X70. Z3.
G96 S200 M03
G71 P10 Q20 U-0.4 W0.1 D2. F0.3
;           ^^^^^ allowance-sign
N10 G00 X20.
G01 Z-10.
X40. Z-20.
; @ uncompensated-contour
N20 X60. Z-30.
G70 P10 Q20 F0.1
G00 X50. Z3.
G71 P10 Q20 U0.4 W0.1 D2. F0.3
; @ start-inside-contour
G70 P10 Q20 F0.1
G00 X70. Z-15.
G71 P10 Q20 U0.4 W0.1 D2. F0.3
; @ start-inside-contour
G70 P10 Q20 F0.1
G00 X10. Z3.
; An inside (ID) contour, started from inside: U must be negative.
G71 P30 Q40 U0.4 W0.1 D2. F0.3
;           ^^^^ allowance-sign
N30 G00 X40.
G01 Z-10.
N40 X30.
G70 P30 Q40 F0.1
G00 X70. Z3.
G72 P50 Q60 U0.4 W0.1 D2. F0.3
; @ no-finishing-pass
N50 G01 Z-5.
G04 P100
; @ non-contour-content
;   ^^^^ dwell-in-milliseconds
M08
; @ non-contour-content
X20.
N60 G02 X30. Z-10. R5.
G73 P70 Q80 U0.4 W0.1 I3. K2. D3. F0.3
N70 G02 X20. Z-5. R15.
; @ contour-start-not-linear
N80 G01 X40. Z-20.
G70 P70 Q80 F0.1
G00 X70. Z3.
; G70 without a roughing cycle before it is legal (rule 33): nothing to flag.
G70 P90 Q95 F0.1
N90 G00 X20.
N95 G01 Z-10.
; No allowance: the roughing is the finish. The move that cancels the
; compensation leaves the contour, beyond the start point.
G00 X50. Z3.
G71 P100 Q110 U0 W0 D2. F0.3
N100 G00 X40.
G01 Z-10.
N110 G01 G40 X55.
G00 X70. Z100.
M30
