(Lathe manual section 10 E19, lines 001:2826-2839: G90 turning passes.)
(OCR fixes: the figure labels "N1" on a line of its own, "N2" after "Z-250.", "N4" after)
(T101 and "30" after the last G53 block are removed, and "Z- 30." is joined to "Z-30.".)
G53 X-200. Z-250.
T101
G96 S210 M3
G54 G00 X52. Z3.
N1 G90 X45. Z-30. F0.3
N2 X40. (U-12)
N3 X35. (U-17)
N4 X30. (U-22)
N5 X25. (U-27)
G00 G53 X-200. Z-250.
M30
