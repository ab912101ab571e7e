"""The job machinery around a script: the ``graphsdg`` command line and what it runs. Job specs, running a script or
a folder of scripts, Ray scale-out, the GPU each process renders on, kernel warmup and the demo scene."""
