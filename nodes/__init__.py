"""graphsdg's node library: every node type a graph can hold, one module per family.

Importing this package registers the node types with the runtime's registries;
``import graphsdg`` does so. The runtime itself never imports a concrete node.
"""
from . import annotators, isaac_annotators, sensor_annotators  # noqa: F401  (register annotator types)
from . import depth_sensor_annotators  # noqa: F401  (single-view depth sensor annotator types)
from . import create, distributions, get, modify, physics, randomizers, triggers  # noqa: F401  (register node types)
from . import domain_randomization  # noqa: F401  (physics domain-randomization node types)
from . import sensor_creators  # noqa: F401  (rep.create.omni_lidar / omni_radar node types)

from graphsdg.annotate.annotator import AnnotatorRegistry as _AnnotatorRegistry  # noqa: E402

# the annotators graphsdg ships (Replicator's DEFAULT_ANNOTATORS list; scripts may append their own)
_AnnotatorRegistry._default_annotators.extend(
    n for n in _AnnotatorRegistry.get_registered_annotators() if n not in _AnnotatorRegistry._default_annotators)
