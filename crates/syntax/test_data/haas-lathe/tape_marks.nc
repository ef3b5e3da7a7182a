
  % (opening mark)
O1 (FIRST)
G0 X1.
M30
O2 (SECOND)
M99
%
