surface: square.s 3
