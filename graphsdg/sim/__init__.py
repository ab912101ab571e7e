"""MuJoCo: the stage compiler, live sync, physics time."""
