O1002 (VALUES OF WORDS)
G50 S2000
G54 G00 X50. Z2.
G97 S800 M03
G04 P500
;   ^^^^ dwell-in-milliseconds
; With a decimal point P counts seconds: nothing to say.
G04 P1.5
G04
; @ dwell-without-p
G04 X1.
; @ dwell-without-p
G00 X62 Z0
;   ^^^ axis-without-point
G01 U-2 W0 F0.2
;   ^^^ axis-without-point
G00 X40. Z5.
G71 P10 Q20 U0.3 W0.1 F0.3
; @ cycle-without-depth
N10 G00 X20.
N20 G01 Z-10.
G72 P10 Q20 D-1. F0.3
;           ^^^^ cycle-without-depth
G73 P10 Q20 D2.5 F0.3
;           ^^^^ cycle-without-depth
G73 P10 Q20 D4. F0.3
G70 P10 Q20
G00 X0 Z3.
G83 Z-20. R3. Q2. I3. F0.1
;             ^^^ peck-with-q-and-ijk
G83 Z-20. R3. Q0 F0.1
;             ^^ step-not-positive
G83 Z-20. R3. I3. J0 K-1. F0.1
;                 ^^ step-not-positive
;                    ^^^^ step-not-positive
G83 Z-20. R3. P200 Q2. F0.1
;             ^^^^ dwell-in-milliseconds
G81 Z-10. F0.1
; @ drilling-without-r
G80
G00 X60.
G75 X40. Z-20. I0 K2. F0.1
;              ^^ step-not-positive
G76 X27. Z-30. K1.5 D0.3 A60. P1 F2.
;                        ^^^^ thread-angle-with-point
G76 X27. Z-30. K-1.5 D0.3 A60 P5 F2.
;              ^^^^^ thread-height-negative
;                             ^^ thread-method
G76 X27. Z-30. K1.5 D0.3 A29.5 P2 F2.
;                        ^^^^^ thread-angle-with-point
G00 X60. Z100.
M30
