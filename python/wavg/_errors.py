"""Exceptions raised by wavg."""


class WavgError(Exception):
    """Base class of every error the wavg library reports."""


class InvalidMeshError(WavgError, ValueError):
    """The mesh is not a valid oriented manifold (or not suitable for the operation).

    ``problems`` lists what is wrong, one string per problem.
    """

    def __init__(self, message: str = "", problems=None):
        super().__init__(message)
        self.problems = list(problems) if problems is not None else [message]


class InvalidArgumentError(WavgError, ValueError):
    """The library refused an argument (out of range or malformed)."""


class WavgIOError(WavgError, OSError):
    """A file could not be read, parsed or written."""


class NoSolutionError(WavgError):
    """A single question has no answer (batches report this in their ``ok`` mask)."""


class CancelledError(WavgError):
    """The progress callable asked to stop."""


class OutOfMemoryError(WavgError, MemoryError):
    """A precomputation would need more memory than the machine has available.

    Refused before it starts; the message gives the estimate and the available memory.
    """
