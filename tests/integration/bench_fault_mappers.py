"""A mapper that fails on purpose, for the runner's failure-isolation tests.

Tests install it as the plugin method ``fault`` (the ``fault_plugin`` fixture); the
cell child processes import it from the test folder (the runner hands them
its ``sys.path``). Otherwise it behaves like dead reckoning, so ``mode = "ok"``
and ``mode = "slow"`` give real, evaluable runs.
"""

from __future__ import annotations

import os
import signal
import time
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict

from albot1.contract import MapperOutput
from albot1.data.model import Frame
from albot1.methods.baselines.odometry import OdometryConfig, OdometryMapper


class FaultConfig(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    mode: Literal["ok", "slow", "raise", "hang", "memory", "crash", "exit", "os-exit", "interrupt"] = "ok"
    at_scan: int = 5
    sleep_s: float = 0.01


class FaultMapper:
    name: ClassVar[str] = "fault"
    config_model: ClassVar[type[BaseModel]] = FaultConfig
    presets: ClassVar[dict[str, dict[str, Any]]] = {"default": FaultConfig().model_dump()}

    def __init__(self, config: FaultConfig, *, seed: int = 0) -> None:
        self.config = config
        self._inner = OdometryMapper(OdometryConfig(), seed=seed)
        self._hoard: list[np.ndarray] = []

    def process(self, frame: Frame) -> None:
        mode = self.config.mode
        if mode == "slow":
            time.sleep(self.config.sleep_s)
        if frame.index == self.config.at_scan:
            if mode == "raise":
                raise RuntimeError(f"injected fault at scan {frame.index}")
            if mode == "hang":
                time.sleep(3600)
            if mode == "memory":
                while True:  # 256 MiB at a time until the supervisor kills it for its memory limit
                    self._hoard.append(np.ones(32 * 2**20))
            if mode == "crash":
                os.kill(os.getpid(), signal.SIGSEGV)
            if mode == "exit":  # a method must not end the process: the runner turns this into its error
                raise SystemExit(0)
            if mode == "interrupt":  # raised, not a Ctrl-C
                raise KeyboardInterrupt
            if mode == "os-exit":  # uncatchable: the cell ends with code 0 and no run
                os._exit(0)
        self._inner.process(frame)

    def finish(self) -> MapperOutput:
        return self._inner.finish()
