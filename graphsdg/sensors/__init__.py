"""Ray-cast sensors over the live MuJoCo model. Lidar and radar scans, their USD schemas and profiles.

The room sits beside ``render/``: it reads the compiled scene (``sim/``) and the stage (``stage/``) and casts
rays with MuJoCo (``mj_multiRay`` on the CPU, MuJoCo Warp on a GPU). ``docs/sensors.md`` describes the sensor
models; Isaac's sensor APIs over it are in ``graphsdg/compat/`` (``sensors_rtx*.py``).

Importing the package itself does nothing: ``import graphsdg`` registers the sensor USD schemas
(:mod:`graphsdg.stage.sensor_schemas`) before anything makes a stage.
"""
