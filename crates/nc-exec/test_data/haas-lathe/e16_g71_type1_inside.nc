O1234
(Lathe manual section 10 E16, lines 001:1872-1894: G71 Type I, inside turning.)
(The manual prints a template: X.., Z.., Z..., R.. and the bare "X Z" of the start point)
(stand for the values of a figure that is lost. The values here are chosen for the test:)
(a bore from a drilled hole of 20 mm, 60 mm at the mouth, a 45 degree chamfer, steps)
(to 40 and 30 mm with R5 roundings; the start point X20. Z3. lies on the drilled hole.)
G50 S3000
G00 G53 X-100. Z-250.
T101
G96 S200 M3
G54 G00 X20. Z3. ( P0 )
G71 P1 Q8 U-0.3 W0.1 D4. F0.3
N1 G00 G41 X60.
N2 G01 Z0.
N3 X50. Z-5.
N4 Z-20.
N5 G03 X40. Z-25. R5.
N6 G01 Z-35.
N7 G02 X30. Z-40. R5.
N8 G00 G40 X18.
G00 G53 X-100. Z-250.
T303
G96 S220 M3
G54 G00 X20. Z3. (P0)
G70 P1 Q8 F0.1
G00 G53 X-100. Z-250.
M30
