"""Pictures of runs: the offscreen top-down render (`render`), matplotlib figures (`plots`) and
videos replayed from a log (`video`)."""
