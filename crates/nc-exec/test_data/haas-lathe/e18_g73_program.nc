O1234
(Lathe manual section 10 E18, lines 001:2184-2206: G73 contour-parallel roughing.)
(OCR fix: the manual's G73 block is split over two lines, "D4." then "F0.3"; joined here.)
(The manual prints a template: X.., Z.., Z-.. and R.. stand for the values of a figure)
(that is lost. The values here are chosen for the test: a forged blank about I9. K8. over)
(the part, a shaft of 20 mm with an R10 rounding, an R5 fillet, a shoulder and a taper.)
G50 S3000
G00 G53 X-100. Z-250.
T101
G96 S200 M3
G54 G00 X80. Z10. (P0)
G73 P10 Q16 U0.3 W0.1 I9. K8. D4. F0.3
N10 G00 G42 X20. Z1.
N11 G01 Z-10.
N12 G03 X40. Z-20. R10.
N13 G02 X50. Z-25. R5.
N14 G01 X60.
N15 X70. Z-40.
N16 G00 G40 X80.
G53 X-100. Z-200.
T303
G96 S220 M3
G54 G00 X80. Z10. (P0)
G70 P10 Q16 F0.1
G00 G53 X-100. Z-200.
M30
