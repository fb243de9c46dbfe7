"""The part from its CAD (docs/cad_import.md): a STEP file read with OpenCascade (``cadquery-ocp``)
into an XCAF document; its holes (``holes.py``, from the cylindrical faces of ``cylinders.py``,
their ends in ``hole_ends.py``), its semantic PMI (``pmi.py``: datums, position and size
tolerances of AP242, with ``pmi_doc.py``, ``pmi_tolerances.py`` and ``pmi_graph.py``, the STEP
entity graph where XCAF has no faces) and its collision mesh (``mesh.py``); ``part.py`` puts
them together.

Importing this package does not load OpenCascade; its modules do.
"""
