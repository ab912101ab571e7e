"""The job machinery around a script: the ``graphsdg`` command line and what it runs. Job specs, running a script or
a folder of scripts, Ray scale-out, kernel warmup, the demo scene and the asset thumbnails docs tool."""
