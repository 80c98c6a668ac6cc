"""Synthetic office worlds with exact ground truth, embedded in the package.

Pure geometry and simulation, no I/O: ``floorplan`` (corridors, rooms,
doorways, furniture -> wall segments), ``route`` (waypoints -> scan poses,
continuous or start-stop), ``lidar`` (ray-cast 2D laser), ``odometry``
(seeded error model), ``layouts`` (the embedded plans and routes) and
``worlds`` (the named registry: ``WORLDS``, ``load_world``,
``world_geometry``, ``doorway_crossings``). See docs/synthetic-worlds.md.
"""

from albot1.data.synthetic.worlds import WORLDS, WorldSpec, doorway_crossings, load_world, world_geometry

__all__ = ["WORLDS", "WorldSpec", "doorway_crossings", "load_world", "world_geometry"]
