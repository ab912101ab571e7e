"""The job machinery around a script: the ``graphsdg`` command line, job specs, running a script, frame
plans for shards and resumes, Ray scale-out, interrupts, progress and each process's share of the cores."""
