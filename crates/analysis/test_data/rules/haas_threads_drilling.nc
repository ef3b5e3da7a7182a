O1006 (THREADS AND DRILLING)
G50 S2000
G54 G00 X40. Z3.
G97 S800 M03
G32 Z-20.
; @ thread-without-pitch
G00 X50.
Z3.
X19.
G32 Z-20. F2.
G00 X50.
G96 S100
G92 X30. Z-20. F2.
; @ thread-under-css
X29.
G97 S800
M23
G92 X28. Z-20. F2.
; @ thread-chamfer-shortens
X27.5
G76 X27. Z-20. K1.2 D0.3 A60 P1 F2.
; @ thread-chamfer-shortens
M24
G76 X27. Z-20. K1.2 D0.3 A60 P1 F2.
G00 X0 Z3.
G81 Z-10. R3. F0.1
Z-12.
; @ drilling-repeats
W-2.
; @ drilling-repeats
; L0: the cycle does not run at this position.
Z-14. L0
G80
G00 X60. Z100.
M30
