line style: cylinder
contour sides: 8
tropism: T: 1 0 0 E: 0.2
