-20.000000 -20.0034000 -19.9974000
-10.000000 -10.0036000 -9.9976000
0.000000 -0.0030000 0.0030000
10.000000 9.9984000 10.0044000
20.000000 20.0006000 20.0066000
# eical comp, joint 0 (x): test table
# COMP_FILE_TYPE = 0: nominal, actual moving +, actual moving - (mm); actual = nominal + deviation
