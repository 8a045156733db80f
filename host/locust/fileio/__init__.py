"""Every file the toolkit writes goes through here: ``from locust.fileio import ...``.

- :mod:`.writes`: where a write lands (a link followed only within its folder, a read-only or
  non-regular file refused), atomic writes through a temporary beside the file (read back
  before it replaces the old one, temporaries of a killed writer removed), folders made and
  never reused, strict JSON.
- :mod:`.locks`: ``flock`` locks for an update of a file (``locked``) or a folder being written
  (``claim_folder``).
- :mod:`.opencv`: a name OpenCV can open whatever bytes a file's name holds, and a video it
  wrote read back.
"""

from .locks import claim_folder, locked, try_lock
from .opencv import check_encoded, opencv_path
from .writes import (
    DISK_HINT,
    atomic_write_bytes,
    atomic_write_json,
    atomic_write_text,
    check_can_make,
    check_distinct,
    json_text,
    link_target,
    make_folder,
    refuse_read_only_folder,
    remove_stale_temporaries,
    storable,
    temp_beside,
    unique_dir,
    unwind_on_termination,
    write_error,
    write_target,
)

__all__ = ["DISK_HINT", "atomic_write_bytes", "atomic_write_json", "atomic_write_text", "check_can_make",
           "check_distinct", "check_encoded", "claim_folder", "json_text", "link_target", "locked", "make_folder",
           "opencv_path", "refuse_read_only_folder", "remove_stale_temporaries", "storable", "temp_beside",
           "try_lock", "unique_dir", "unwind_on_termination", "write_error", "write_target"]
