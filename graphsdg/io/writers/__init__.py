"""Built-in writers; importing this package registers them."""
from graphsdg.io.writer import WriterRegistry
from graphsdg.io.writers.basic import BasicWriter
from graphsdg.io.writers.bop import BopWriter
from graphsdg.io.writers.coco import CocoWriter
from graphsdg.io.writers.cosmos import CosmosWriter
from graphsdg.io.writers.dope import DOPEWriter
from graphsdg.io.writers.kitti import KittiWriter
from graphsdg.io.writers.point_cloud import PointCloudWriter
from graphsdg.io.writers.pose import PoseWriter
from graphsdg.io.writers.pytorch import PytorchListener, PytorchWriter
from graphsdg.io.writers.webdataset import WebDatasetWriter
from graphsdg.io.writers.yolo import YoloWriter
from graphsdg.io.writers.ycb_video import YCBVideoWriter

for _writer in (BasicWriter, BopWriter, CocoWriter, CosmosWriter, KittiWriter, PointCloudWriter, PoseWriter,
                WebDatasetWriter, YoloWriter, DOPEWriter, PytorchWriter, YCBVideoWriter):
    WriterRegistry.register(_writer, category="default")

__all__ = ["BasicWriter", "BopWriter", "CocoWriter", "CosmosWriter", "KittiWriter", "PointCloudWriter", "PoseWriter",
           "WebDatasetWriter", "YoloWriter", "DOPEWriter", "PytorchListener", "PytorchWriter", "YCBVideoWriter"]
