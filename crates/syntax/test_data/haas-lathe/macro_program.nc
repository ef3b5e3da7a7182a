%
O9010 (BOLT CIRCLE)
#1 = 0 ; counter
#2 = #5 * 2.
#[#2 + 100] = -#5
#3=SIN[30.]*COS[#1]+ATAN[#1]/[2.]-SQRT[ABS[#2]]
#4 = ROUND[#3] MOD 3 + FIX[#2 / 4] - FUP[.5]
IF [#1 EQ 0] GOTO 20
IF [[#1 GT 1] AND [#2 LE 10.]] THEN #6 = #1 XOR 1
WHILE [#1 LT 10] DO1
G01 X[#1 * 2.] Z-#2 F0.1
#1 = #1 + 1
END1
/1 N20 G65 P9010 A1. B2.
N30 GOTO #4
DO2
END2
M99
%
anything after the closing mark is never read
