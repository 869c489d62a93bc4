"""Studies that reproduce published findings from jaxform runs (``jaxform study``).

- :mod:`jaxform.study.plan`: the runs of the source paper's study and when a finished one is reused.
- :mod:`jaxform.study.measures`: what is measured on a run folder.
- :mod:`jaxform.study.claims`: the paper's findings as claims judged on those measures.
- :mod:`jaxform.study.report`: ``report.md``, ``claims.json``, figures and sections from the run folders.
"""
