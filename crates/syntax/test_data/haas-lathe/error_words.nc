G01 X (unclosed comment
Z- 30. X 10.
x1.
12 -
= %
O
, @
/1 X1. / Y2.
roughing pass
G00 Z,15 (a comma typed for a point)
