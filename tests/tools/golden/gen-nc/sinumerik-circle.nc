%_N_EICAL_CIRCLE_MPF
;$PATH=/_N_MPF_DIR
; eical circle R10 F2500 both, 1 revolutions, plane xy
G90 G71 G17 G64 ; continuous path: the arcs are one blended move
G0 X7.0711 Y7.0711
G4 F0.400
M101
G4 F0.100
G3 X-7.0711 Y7.0711 I-7.0711 J-7.0711 F2500 ; ramp-in
M102
G3 X-7.0711 Y7.0711 I7.0711 J-7.0711
M102
G3 X-7.0711 Y-7.0711 I7.0711 J-7.0711 ; ramp-out
G4 F0.200 ; reversal: rest before the opposite direction
G2 X-7.0711 Y7.0711 I7.0711 J7.0711 F2500 ; ramp-in
M102
G2 X-7.0711 Y7.0711 I7.0711 J-7.0711
M102
G2 X7.0711 Y7.0711 I7.0711 J-7.0711 ; ramp-out
G4 F0.400
M103
G4 F0.100
M30
