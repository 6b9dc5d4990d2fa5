"""One way to load an FMU through fmpy for the FMU tests (test_fmu, test_fuzz_fmu,
test_reliability3): an FMU2Slave instantiated with callbacks that keep its log."""

from __future__ import annotations

from fmpy.fmi2 import (
    FMU2Slave,
    calloc,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    free,
)


def logging_callbacks(logs: list[str]) -> fmi2CallbackFunctions:
    """fmi2 callbacks whose logger appends each message to ``logs``; keep the object alive
    as long as the instance (the FMU calls through it)."""
    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, cat, msg: logs.append(msg.decode()))
    cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    return cb


def instantiate(folder: str, md, instance: str, logs: list[str] | None):
    """(FMU2Slave, callbacks) of the extracted FMU in ``folder`` with model description ``md``,
    instantiated; with ``logs`` None, fmpy's own callbacks (callbacks is then None)."""
    cb = None if logs is None else logging_callbacks(logs)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName=instance)
    fmu.instantiate(callbacks=cb)
    return fmu, cb
