"""voiga post-processing: read result files, evaluate displaced fields, plot.

``post.reader`` is the only module that reads result files (schema:
``docs/hdf5.md``); ``post.field`` evaluates a body's displaced map exactly
(including the varying-order contact row); ``post.plot`` draws figures.
Command line: ``python -m post --help``; documentation: ``docs/post.md``.
"""
