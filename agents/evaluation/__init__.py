"""Evaluation: episodes and summaries with intervals (``evaluate``), the train/test/bundled
benchmark protocol (``benchmark``), the statistics (``stats``) and the Ray backend
(``ray_eval``)."""
