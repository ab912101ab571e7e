"""PytorchWriter and PytorchListener: each frame's RGB images handed to Python as one batched PyTorch tensor.

Isaac Sim's (deprecated) ``PytorchWriter``: per frame, the ``LdrColor`` (rgb) image of every attached render
product is stacked into a ``(N, H, W, 4)`` uint8 tensor on ``device`` and given to the listener
(``listener.write_data({"pytorch_rgb": tensor, "device": device})``);
:meth:`PytorchListener.get_rgb_data` returns the latest batch as ``(N, 3, H, W)``. With ``output_dir``, each
image is also written as ``rgb_{frame}_{name}.png``, ``name`` being the render product's name with several
products and ``LdrColor`` with one (Isaac's file names).

PyTorch is not a graphsdg dependency: the writer needs it (and says so when it is missing); the listener's
batches are PyTorch tensors by contract, so it has nothing to hand out without it.
"""
from __future__ import annotations

import importlib
from typing import Any

import numpy as np

from graphsdg.annotate.annotator import AnnotatorRegistry
from graphsdg.io.writer import Writer
from graphsdg.io.writers import arguments

TORCH_HINT = "install PyTorch (pip install torch; see https://pytorch.org for the CUDA builds)"


def require_torch(what: str) -> Any:
    """The ``torch`` module, or an ImportError saying ``what`` needs it and how to install it."""
    try:
        return importlib.import_module("torch")
    except ImportError as exc:
        raise ImportError(f"{what} hands out PyTorch tensors and needs PyTorch, which is not installed ({exc}); "
                          f"{TORCH_HINT}") from exc


def rgb_batch(data: dict) -> tuple[np.ndarray, list[str]]:
    """The ``LdrColor`` images of one legacy ``data`` dict stacked (N, H, W, C), and each one's file-name part."""
    keys = [k for k in data if k.startswith("LdrColor")]
    if not keys:
        raise KeyError(f"PytorchWriter: the frame has no LdrColor output; it has {sorted(data)}")
    images = [np.asarray(data[k]) for k in keys]
    shapes = {im.shape for im in images}
    if len(shapes) > 1:
        raise ValueError(f"PytorchWriter batches images of one size; its render products gave {sorted(shapes)}")
    return np.stack(images), [k.split("-")[-1] for k in keys]


class PytorchListener:
    """Keeps the latest data a :class:`PytorchWriter` sent (``data``) and hands out its RGB batch."""

    def __init__(self) -> None:
        self.data: dict = {}

    def write_data(self, data: dict) -> None:
        """Merge a writer's latest ``data`` into what the listener holds."""
        self.data.update(data)

    def get_rgb_data(self) -> Any:
        """The latest RGB batch as a ``(N, 3, H, W)`` tensor (alpha dropped), or ``None`` before any frame."""
        images = self.data.get("pytorch_rgb")
        if images is None:
            return None
        require_torch("PytorchListener.get_rgb_data")
        return images[..., :3].permute(0, 3, 1, 2)


class PytorchWriter(Writer):
    """Sends each frame's RGB images to a :class:`PytorchListener` as one tensor (see the module docstring)."""

    def __init__(self, listener: PytorchListener, output_dir: str | None = None, tiled_sensor: bool = False,
                 device: str = "cuda") -> None:
        name = type(self).__name__
        self._torch = require_torch(name)
        if not callable(getattr(listener, "write_data", None)):
            raise TypeError(f"{name}: listener must have a write_data(dict) method (a PytorchListener), "
                            f"got {type(listener).__name__}")
        if tiled_sensor:
            raise ValueError(f"{name}: tiled_sensor=True reads RTX's tiled sensor output (RtxSensorGpu), which "
                             f"graphsdg's renderers do not produce; use one render product per camera")
        self.version = "0.0.1"
        self.backend = arguments.output_backend(name, output_dir) if output_dir else None
        self._backend = self.backend
        self._output_dir = getattr(self.backend, "output_dir", None)
        self._frame_id = 0
        self.listener = listener
        self.device = device
        self.annotators = [AnnotatorRegistry.get_annotator("LdrColor")]

    def write(self, data: dict) -> None:
        batch, names = rgb_batch(data)
        if self.backend is not None:
            for image, name in zip(batch, names):
                self.backend.write_image(f"rgb_{self._frame_id}_{name}.png", image)
        tensor = self._torch.from_numpy(np.ascontiguousarray(batch)).to(self.device)
        self.listener.write_data({"pytorch_rgb": tensor, "device": self.device})
        self._frame_id += 1
