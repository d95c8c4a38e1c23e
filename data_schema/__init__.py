"""data_schema: the HDF5 layouts shared by the producer (tablegen) and the consumer (surrogate).

Every file carries two root attributes: ``file_type`` (a string naming the
layout) and ``format_version`` (major, minor). A reader accepts any minor
version of its major version. Every reader opens files through
:func:`check_file`, which names the file and what is wrong with it.
The prose description of each layout is in ``docs/format.md``.
"""

from data_schema.common import DataFormatError, check_file
from data_schema.output import OutputError, check_output
from data_schema.samples import (
    SAMPLES_FILE_TYPE,
    SAMPLES_VERSION,
    STATUS_FAILED,
    STATUS_NAMES,
    STATUS_REBOUNDED,
    STATUS_TRAPPED,
    SampleSet,
    read_samples,
    write_samples,
)

__all__ = [
    "DataFormatError", "OutputError", "check_file", "check_output",
    "SAMPLES_FILE_TYPE", "SAMPLES_VERSION", "STATUS_FAILED", "STATUS_NAMES",
    "STATUS_REBOUNDED", "STATUS_TRAPPED", "SampleSet", "read_samples", "write_samples",
]
