projection: parallel
render mode: shaded
line style: cylinder
light: O: 10 10 -5
