"""Drawing the graph as a picture (PNG) without Graphviz.

The layout is layered by topological generation, left to right: triggers and
ungated inputs in the first column, each node one column right of its latest
input. Within a column nodes are ordered by the mean row of their inputs (a
few barycentre sweeps keep edges from crossing). Nodes are boxes coloured by
family (triggers are diamonds, distributions rounded); gating edges are dashed,
data edges solid with their ports written next to the arrow head.

Example:
    >>> import graphsdg as rep
    >>> _ = rep.stage.new_stage()
    >>> with rep.trigger.on_frame():
    ...     _ = rep.create.light(light_type="Sphere", intensity=rep.distribution.uniform(1e3, 2e3))
    >>> image = rep.graph.draw()
    >>> image.ndim, image.shape[2]
    (3, 3)
"""
from __future__ import annotations

from dataclasses import dataclass

import networkx as nx
import numpy as np
from PIL import Image, ImageDraw, ImageFont

from graphsdg.graph.export import to_dict

FAMILY_COLOURS = {
    "trigger": (255, 214, 102), "distribution": (173, 216, 230), "create": (183, 228, 170),
    "get": (200, 230, 201), "modify": (244, 194, 194), "randomizer": (230, 190, 240),
}
DEFAULT_COLOUR = (220, 220, 220)
BACKGROUND = (255, 255, 255)
INK = (30, 30, 30)
PAD_X, PAD_Y, COLUMN_GAP, ROW_GAP, MARGIN = 10, 6, 130, 22, 20


@dataclass
class Box:
    """Where one node is drawn (pixels, top-left origin)."""

    name: str
    type_name: str
    family: str
    x: int
    y: int
    width: int
    height: int

    @property
    def centre(self) -> tuple[int, int]:
        return self.x + self.width // 2, self.y + self.height // 2


def _font(size: int) -> ImageFont.ImageFont:
    try:
        return ImageFont.load_default(size=size)
    except TypeError:      # Pillow < 10.1 has only the fixed bitmap font
        return ImageFont.load_default()


def _dag(structure: dict) -> nx.DiGraph:
    dag = nx.DiGraph()
    for n in structure["nodes"]:
        dag.add_node(n["name"], **n)
    for e in structure["edges"]:
        dag.add_edge(e["from"], e["to"], kind=e["kind"], ports=e["ports"])
    return dag


def _columns(dag: nx.DiGraph, order: list[str]) -> list[list[str]]:
    rank = {name: i for i, name in enumerate(order)}
    columns = [sorted(gen, key=rank.get) for gen in nx.topological_generations(dag)]
    for _ in range(4):   # barycentre sweeps, forwards then backwards
        for cols, neighbours in ((columns[1:], dag.predecessors), (columns[-2::-1], dag.successors)):
            for col in cols:
                pos = {n: i for c in columns for i, n in enumerate(c)}
                def key(n, pos=pos, neighbours=neighbours):
                    near = [pos[m] for m in neighbours(n)]
                    return (sum(near) / len(near) if near else pos[n], rank[n])
                col.sort(key=key)
    return columns


def layout(graph=None, structure: dict | None = None) -> tuple[list[Box], tuple[int, int]]:
    """The boxes of every node and the picture's (width, height) for ``graph`` (or a :func:`to_dict`)."""
    structure = structure if structure is not None else to_dict(graph)
    dag = _dag(structure)
    font = _font(13)
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    sizes = {}
    for name, data in dag.nodes(data=True):
        w = max(probe.textlength(name, font=font), probe.textlength(data["type"], font=_font(11)))
        sizes[name] = (int(w) + 2 * PAD_X + (24 if data["family"] == "trigger" else 0), 13 + 11 + 3 * PAD_Y)
    boxes: list[Box] = []
    x = MARGIN
    height = 0
    for col in _columns(dag, [n["name"] for n in structure["nodes"]]):
        col_width = max(sizes[n][0] for n in col)
        y = MARGIN
        for name in col:
            w, h = sizes[name]
            data = dag.nodes[name]
            boxes.append(Box(name, data["type"], data["family"], x + (col_width - w) // 2, y, w, h))
            y += h + ROW_GAP
        height = max(height, y - ROW_GAP + MARGIN)
        x += col_width + COLUMN_GAP
    width = max(x - COLUMN_GAP + MARGIN, 2 * MARGIN)
    return boxes, (width, max(height, 2 * MARGIN))


def _dashed(draw: ImageDraw.ImageDraw, points: list[tuple[float, float]], dash: float = 6.0) -> None:
    drawn, on = 0.0, True
    for (x0, y0), (x1, y1) in zip(points, points[1:]):
        seg = float(np.hypot(x1 - x0, y1 - y0))
        if seg == 0:
            continue
        t = 0.0
        while t < seg:
            step = min(dash - drawn, seg - t)
            if on:
                a, b = t / seg, (t + step) / seg
                draw.line([(x0 + (x1 - x0) * a, y0 + (y1 - y0) * a), (x0 + (x1 - x0) * b, y0 + (y1 - y0) * b)],
                          fill=INK, width=1)
            t += step
            drawn += step
            if drawn >= dash:
                drawn, on = 0.0, not on


def _curve(p0: tuple[int, int], p1: tuple[int, int], steps: int = 24) -> list[tuple[float, float]]:
    """A horizontal S-curve (cubic Bezier) from ``p0`` to ``p1``."""
    (x0, y0), (x1, y1) = p0, p1
    dx = max(abs(x1 - x0) / 2, 20)
    c0, c1 = (x0 + dx, y0), (x1 - dx, y1)
    pts = []
    for t in np.linspace(0, 1, steps):
        u = 1 - t
        pts.append((u ** 3 * x0 + 3 * u * u * t * c0[0] + 3 * u * t * t * c1[0] + t ** 3 * x1,
                    u ** 3 * y0 + 3 * u * u * t * c0[1] + 3 * u * t * t * c1[1] + t ** 3 * y1))
    return pts


def _edge(pen: ImageDraw.ImageDraw, e: dict, a: Box, b: Box, font) -> None:
    start, end = (a.x + a.width, a.centre[1]), (b.x, e["end_y"])
    points = _curve(start, end)
    if e["kind"] == "exec":
        _dashed(pen, points)
    else:
        pen.line(points, fill=INK, width=1)
        label = ", ".join(f"{p}->{q}" for p, q in e["ports"])
        pen.text((start[0] + 4, start[1] - 12), label, fill=(90, 90, 90), font=font)
    tip, tail = np.array(points[-1]), np.array(points[-3])
    d = (tip - tail) / (np.linalg.norm(tip - tail) or 1.0)
    n = np.array([-d[1], d[0]])
    pen.polygon([tuple(tip), tuple(tip - 8 * d + 4 * n), tuple(tip - 8 * d - 4 * n)], fill=INK)


def draw(graph=None, path: str | None = None, structure: dict | None = None) -> np.ndarray:
    """The graph as an RGB image (H, W, 3); also saved as PNG to ``path`` if given.

    ``structure`` draws a graph exported with :func:`~graphsdg.graph.to_dict` (or read
    back from its JSON) instead of a live graph.
    """
    structure = structure if structure is not None else to_dict(graph)
    boxes, size = layout(structure=structure)
    image = Image.new("RGB", size, BACKGROUND)
    pen = ImageDraw.Draw(image)
    where = {b.name: b for b in boxes}
    small = _font(10)
    if not boxes:
        pen.text((MARGIN, MARGIN), "graph: empty", fill=INK, font=_font(13))
    arrivals: dict[str, list[dict]] = {}
    for e in structure["edges"]:
        arrivals.setdefault(e["to"], []).append(e)
    for target, edges in arrivals.items():
        b = where[target]
        edges.sort(key=lambda e: where[e["from"]].centre[1])
        for i, e in enumerate(edges):     # spread the arrows over the target's left side
            e = dict(e, end_y=b.y + (i + 1) * b.height / (len(edges) + 1))
            _edge(pen, e, where[e["from"]], b, small)
    for box in boxes:
        fill = FAMILY_COLOURS.get(box.family, DEFAULT_COLOUR)
        x0, y0, x1, y1 = box.x, box.y, box.x + box.width, box.y + box.height
        if box.family == "trigger":
            cx, cy = box.centre
            pen.polygon([(x0, cy), (x0 + 12, y0), (x1 - 12, y0), (x1, cy), (x1 - 12, y1), (x0 + 12, y1)],
                        fill=fill, outline=INK)
        elif box.family == "distribution":
            pen.rounded_rectangle([x0, y0, x1, y1], radius=box.height // 2, fill=fill, outline=INK)
        else:
            pen.rectangle([x0, y0, x1, y1], fill=fill, outline=INK)
        offset = 12 if box.family == "trigger" else 0
        pen.text((x0 + PAD_X + offset, y0 + PAD_Y), box.name, fill=INK, font=_font(13))
        pen.text((x0 + PAD_X + offset, y0 + 2 * PAD_Y + 13), box.type_name, fill=(70, 70, 70), font=_font(11))
    if path is not None:
        image.save(path)
    return np.asarray(image)
