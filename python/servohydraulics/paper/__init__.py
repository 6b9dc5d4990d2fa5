"""The reproduction of Zhao, French, Shield & Posbergh (2003): the paper's claims
(claims.py), the experiments behind each figure (experiments.py), their evaluation
into table rows (evaluate.py), the figures (figures.py), the report writers
(report.py), the driver (reproduce.py) and the demo (demo.py)."""
