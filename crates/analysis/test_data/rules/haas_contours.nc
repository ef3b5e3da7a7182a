O1000 (P/Q CONTOUR CONTRACT)
G50 S2000
G96 S200 M03
G54 G00 X60. Z2.
G71 P10 Q90 U0.5 W0.1 D2. F0.25
;   ^^^ contour-target-missing
;       ^^^ contour-target-missing
G71 P20 U0.5 W0.1 D2. F0.25
; @ contour-without-p-q
G71 P30 Q20 D2.
;       ^^^ q-before-p
G71 P20 Q30 D2. F0.25
N20 G00 X20.
N25 G01 Z-10. F0.1
;             ^^^^ contour-feed-speed-tool
N26 X30. ,C1.
;        ^^^^ contour-corner-ignored
N27 X25. Z-20.
;   ^^^^ type-i-pocket
;   ^^^^ uncompensated-contour
N30 X40. Z-30.
G72 P40 Q50 D1.
N40 G00 Z-40.
N45 G01 X50. A30.
;            ^^^^ contour-angle-ignored
N46 Z-35.
N50 X60. Z-45.
;        ^^^^^ g72-not-monotonic
M97 P70
;   ^^^ m97-target-missing
M98
; @ call-without-p
GOTO 80
; @ goto-target-missing
N60 G00 X80.
N60 G00 X90.
GOTO 60
; @ ambiguous-block-number
M30
