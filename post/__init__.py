"""voiga post-processing: run cases, read result files, evaluate displaced fields,
plot, export to ParaView.

``post.reader`` is the only module that reads result files (schema:
``docs/hdf5.md``); ``post.field`` evaluates a body's displaced map exactly
(including the varying-order contact row); ``post.plot``, ``post.contact`` and
``post.history`` draw figures; ``post.paraview`` writes the ParaView series;
``post.run`` solves a case and shows it. Command line: ``python -m post --help``;
documentation: ``docs/post.md``.
"""
