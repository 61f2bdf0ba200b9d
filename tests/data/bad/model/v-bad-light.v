line style: cylinder
light: V: 1 x 0
