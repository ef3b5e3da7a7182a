O1007 (PROGRAM START AND END)
G53 X-100. Z-200.
; @ no-motion-code-at-start
T101
G96 S200 M03
; @ css-without-limit
G00 X50. Z2.
G01 Z-10. F0.2
G54 G00 X60. Z2.
; @ no-program-end
O1008 (NO END)
G00 X10. Z2.
; @ no-program-end
O1009 (NO WORK OFFSET)
G00 X10. Z2.
G01 Z-5. F0.2
; @ feed-before-work-offset
M30
O1010 (NO MOTION CODE)
G54 X10. Z2.
; @ no-motion-code-at-start
M30
O1011 (A SUBPROGRAM)
; A subprogram starts from its caller's state, unknown here.
G01 X20. Z-10.
M99
O1012 (NO FEED)
G54 G00 X50. Z2.
G01 Z-5.
;   ^^^^ feed-never-programmed
; Once a program: the same cause.
Z-10.
F0.2
Z-15.
M30
