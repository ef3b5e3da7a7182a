G01 X30. K-3. ( prvý NC-blok)
Z-20. (druhý NC-blok)
