"""QIF 3.0 (ANSI/DMSC QIF 3.0, ISO 23952:2020) results of a run: ``report.qif``.

:func:`write_qif` builds the document from a report.json mapping (:mod:`.document`, one module
per section: :mod:`.datums`, :mod:`.features`, :mod:`.characteristics`), validates it against
the vendored schemas (:mod:`.validator`, ``schema/NOTICE.md``) and writes it; :mod:`.read` reads
a report.qif back. Units in the file: metre and radian (declared in ``FileUnits``).
"""

from cell.review.qif.document import build_qif, inspection_status, write_qif
from cell.review.qif.errors import QifError
from cell.review.qif.validator import validate_file

__all__ = ["QifError", "build_qif", "inspection_status", "validate_file", "write_qif"]
