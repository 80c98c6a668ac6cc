"""albot1-bench: the Albot1 perceptual mapper and SLAM baselines on 2D laser data.

Heavy dependencies (rosbags, kiss-icp, gtsam, shapely, matplotlib) are imported
lazily inside the modules that need them, so ``import albot1`` stays cheap.
"""

__version__ = "0.1.0"
