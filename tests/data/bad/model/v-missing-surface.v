render mode: shaded
surface: nothere.s
