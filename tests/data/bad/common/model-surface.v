surface: s-not-a-number.s
