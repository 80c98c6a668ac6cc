"""MRPT's SLAM applications as baselines: ``mrpt-icp`` (icp-slam) and ``mrpt-rbpf`` (rbpf-slam).

The applications run as subprocesses on a rawlog the project writes itself
(:mod:`albot1.data.loaders.rawlog`); see :mod:`.mapper` and
``docs/baselines.md`` (section MRPT).
"""

from albot1.methods.baselines.mrpt.mapper import MrptIcpMapper, MrptRbpfMapper

__all__ = ["MrptIcpMapper", "MrptRbpfMapper"]
