G71 P10 Q20 U0.3 W0.05 D3. F0.3 (hrubovanie kontúry, definované medzi N10 a N20)
N10 G00 X10.
N20 G00 G40 X75. Z-60.
G70 P10 Q20 F0.1 (hladiaci cyklus kontúry, definovaný medzi N10 a N20)
