line style: cylinder
contour sides: many
