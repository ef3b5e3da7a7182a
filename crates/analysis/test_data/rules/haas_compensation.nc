O1004 (TOOL-NOSE COMPENSATION)
G50 S2000
G54 G00 X60. Z2.
G96 S200 M03
G42 G02 X50. Z-5. R5. F0.2
;   ^^^ compensation-start-on-arc
G00 G40 X60. Z2.
G42
G03 X50. Z-5. R5.
; @ compensation-start-on-arc
G01 X70. Z-20.
G40 G02 X80. Z-25. R5.
;   ^^^ compensation-end-on-arc
G00 X60. Z2.
G41 G01 X20. Z0
G01 Z-10.
G40
G02 X30. Z-15. R5.
; @ compensation-end-on-arc
G00 X60. Z2.
G42 G01 X30. Z0
T202
; @ compensation-left-on
G40 G00 X60. Z2.
G01 X40. Z-10.
;   ^^^^ uncompensated-contour
G01 X50. Z-20.
G00 X60. Z2.
G71 P10 Q20 U0.3 W0.1 D2. F0.3
N10 G00 G42 X20.
G01 Z-10.
N20 X40.
; @ contour-compensation-open
G00 G40 X60. Z2.
G70 P10 Q20
G42 G01 X30. Z0
M30
; @ compensation-left-on
