O1003 (MOTION GEOMETRY)
G50 S2000
G54 G00 X50. Z30.
G97 S800 M03
G03 X80. Z15. R15. F0.2
;   ^^^^ uncompensated-contour
G00 X50. Z30.
; The manual's consistent arcs (E4a, E4c, E4d): not flagged.
G03 X80. Z15. I0 K-15.
G00 X50. Z0
G03 X80. Z-15. I0 K-15.
G00 X50. Z0
G02 X80. Z-15. I15. K0
G00 X50. Z0
G02 X80. Z-15. I15. K-1.
;              ^^^^ impossible-arc
G00 X50. Z0
G02 X80. Z-30. R10.
;              ^^^^ impossible-arc
G00 X50. Z0
G02 X80. Z-15. R-15.
;              ^^^^^ arc-over-half-circle
G00 X50. Z0
G02 X80. Z-15. R15. I15.
;              ^^^^ arc-radius-and-centre
G00 X50. Z0
G02 X80. Z-15.
; @ arc-without-centre
G00 X40. Z2.
; The manual's chamfer (E21): K after a move along X, negative as the next move.
G01 X30. K-3.
Z-20.
G01 X40. I-2.
;        ^^^^ corner-letter-mismatch
Z-30.
G01 X50. Z-35. R2.
;              ^^^ corner-not-between-axis-moves
Z-40.
G01 X60. R3.
;        ^^^ corner-sign-mismatch
Z-50.
G01 Z-55. I2.
;         ^^^ corner-not-between-axis-moves
G00 X70.
G01 A110. X50.
G01 A110. X40. Z-60.
;   ^^^^^ angle-needs-one-axis
G01 Z-60.
G00 X100. Z100.
M30
