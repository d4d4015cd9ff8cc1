"""``vibroimpact paper``: the founding paper reproduced (A. Afsharfard, A. Farshidianfar,
Arch. Appl. Mech. 82 (2012) 977-984) and gone beyond: the job (:mod:`.job`), the
paper's data (:mod:`.data`), the runs beyond it (:mod:`.beyond`), the figures
(:mod:`.plots`) and the report (:mod:`.report`)."""

from vibroimpact.paper.job import run_paper

__all__ = ["run_paper"]
