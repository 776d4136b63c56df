"""How a planner's force becomes motion: the potential fields' forces (`fields`), the governor
that checks the predicted motion against the footprint (`governor`), the evasion of moving
tracks (`evasion`) and the way search on a local map (`gridsearch`)."""
