"""UR10-style palletizing: Isaac Sim's ``BinStacking`` sample, built on graphsdg and MuJoCo.

A six-axis arm of UR10 proportions on a pedestal takes bins off a conveyor and
stacks them on a pallet, six to a layer; bins that arrive upside down are
turned over on a flip helper first. Everything is on the USD stage (the arm as
an articulation of rigid links, revolute joints with drives, bins as rigid
bodies) and simulated by the MuJoCo model graphsdg compiles from it; a
controller runs as a physics callback (see
:mod:`graphsdg.scenarios.palletizing_controller`).

The object has the sample's interface, so the Isaac tutorial's driver runs as is
(``graphsdg run --compat isaac`` maps
``isaacsim.examples.interactive.ur10_palletizing.ur10_palletizing.BinStacking``
here)::

    sample = BinStacking()
    await sample.load_world_async()     # a new stage with the cell
    await sample.on_event_async()       # start the timeline: the robot begins

Which bins arrive upside down is drawn from Python's ``random`` when the world is
loaded (the tutorial seeds it with ``random.seed(42)``). The number of bins is
``num_bins`` or the setting ``/graphsdg/scenarios/palletizing/numBins`` (36, as
in Isaac Sim's demo).

Example:
    >>> import random
    >>> random.seed(42)
    >>> sample = BinStacking(num_bins=2)
    >>> sample.load_world()
    >>> sample.flipped
    [True, True]
    >>> sample.start()
    >>> sample.run_until(lambda: len(sample.placed) == 1, max_seconds=30.0) and sample.placed
    [0]
    >>> sample.stop()
"""
from __future__ import annotations

import random
from typing import Callable

import numpy as np

from graphsdg.base import settings_store as settings
from graphsdg.scenarios import palletizing_cell as cell
from graphsdg.scenarios import ur10
from graphsdg.scenarios.palletizing_controller import Event, PalletizingController
from graphsdg.sim.joints import Frame

CALLBACK = "graphsdg.scenarios.palletizing"
NUM_BINS_SETTING = "/graphsdg/scenarios/palletizing/numBins"
DEFAULT_NUM_BINS = 36
FLIP_PROBABILITY = 0.5


def upside_down_bins(count: int) -> list[bool]:
    """Which of ``count`` bins arrive upside down, drawn from Python's ``random`` four numbers a bin.

    The draws follow Isaac's sample as it spawns a bin (its offset across the belt, two for its yaw, then the
    turn-over draw); the stand-in's belt centres its bins, so the first three are taken only to keep the
    sequence. A bin whose last draw is at most 0.5 arrives upside down: with ``random.seed(42)`` that turns over
    the first two bins, the outcome Isaac's palletizing test records for that seed.

    Example:
        >>> random.seed(42); upside_down_bins(4)
        [True, True, False, False]
    """
    flags = []
    for _ in range(count):
        random.uniform(-0.15, 0.15)
        random.random(), random.random()
        flags.append(random.random() <= FLIP_PROBABILITY)
    return flags


class BinStacking:
    """The palletizing sample: :meth:`load_world_async` builds the cell, :meth:`on_event_async` starts it."""

    def __init__(self, num_bins: int | None = None, layout: cell.CellLayout | None = None) -> None:
        n = num_bins if num_bins is not None else settings.get(NUM_BINS_SETTING, DEFAULT_NUM_BINS)
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= 36:
            raise ValueError(f"BinStacking num_bins (or setting {NUM_BINS_SETTING}) must be an integer from 1 to 36 "
                             f"(six layers of six bins), got {n!r}")
        self.num_bins = n
        self.layout = layout or cell.CellLayout()
        self.flipped: list[bool] = []
        self.controller: PalletizingController | None = None
        self.kinematics: ur10.Ur10Kinematics | None = None

    # ---- Isaac's sample interface ------------------------------------------------------
    async def load_world_async(self) -> None:
        """Build the cell on a new stage (Isaac: load the sample's world)."""
        self.load_world()

    async def on_event_async(self) -> None:
        """Start the palletizing (Isaac: the sample's start button)."""
        self.start()

    async def clear_async(self) -> None:
        self.stop()

    # ---- the same, synchronously -----------------------------------------------------
    def load_world(self) -> None:
        """A new stage holding the cell, the arm at home, bin 0 on the belt and the rest stacked waiting."""
        from graphsdg import stage as stage_ctx
        from graphsdg.engine.runtime import runtime

        self.flipped = upside_down_bins(self.num_bins)
        stage = stage_ctx.new_stage()
        cell.build_cell(stage, self.layout, self.num_bins, self.flipped)
        self.kinematics = ur10.author_arm(stage, cell.ROBOT, Frame(np.zeros(3), np.eye(3)))
        self.suction_joints = cell.author_suction_joints(stage, f"{cell.ROBOT}/wrist_3_link", self.num_bins)
        runtime().sim.sync_dirty_prims()     # compile now, so starting costs nothing
        self.controller = None

    def start(self) -> None:
        """Hook the controller into physics and play the timeline."""
        from graphsdg.engine.runtime import runtime
        if self.kinematics is None:
            raise RuntimeError("BinStacking.start(): load the world first (load_world / load_world_async)")
        sim = runtime().sim
        sim.sync_dirty_prims()
        self.controller = PalletizingController(
            self.layout, self.kinematics, cell.ROBOT, f"{cell.ROBOT}/{ur10.SUCTION_CUP}",
            f"{cell.CELL}/conveyor/Belt", [f"{cell.BINS}/bin_{i}" for i in range(self.num_bins)], self.flipped,
            self.suction_joints)
        sim.add_physics_callback(CALLBACK, self.controller.physics_step)
        runtime().timeline.play()

    def stop(self) -> None:
        """Unhook the controller and pause the timeline."""
        from graphsdg.engine.runtime import runtime
        runtime().sim.remove_physics_callback(CALLBACK)
        runtime().timeline.pause()

    # ---- progress ------------------------------------------------------------------------
    @property
    def placed(self) -> list[int]:
        """Bins on the pallet, in the order they were put there."""
        return list(self.controller.placed) if self.controller else []

    @property
    def events(self) -> list[Event]:
        return list(self.controller.events) if self.controller else []

    def is_done(self) -> bool:
        return bool(self.controller and self.controller.done)

    def run_until(self, condition: Callable[[], bool], max_seconds: float = 600.0) -> bool:
        """App updates (one timeline frame each) until ``condition()`` or ``max_seconds`` of simulated time."""
        from graphsdg import orchestrator
        from graphsdg.engine.runtime import runtime
        timeline = runtime().timeline
        start = timeline.get_current_time()
        while not condition():
            if timeline.get_current_time() - start > max_seconds:
                return False
            if not timeline.is_playing():
                timeline.play()
            orchestrator.update()
        return True
