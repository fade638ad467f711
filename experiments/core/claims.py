"""What a claim is: a published statement an experiment judges from stored
results, with its verdict rule and that rule's thresholds as named data.

An experiment declares its claims beside its grid and its plot
(``Experiment.claims``); the report (experiments.core.report) only renders
them.  A claim's ``judge`` reads the stored results through ``Results`` and
returns its rows: what we measured, the verdict, and one line on why."""
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable

from . import results

HOLDS, PARTLY, FAILS = "holds", "partly", "does not hold"
UNTESTABLE, MISSING = "not testable on this machine", "not measured yet"
VERDICTS = (HOLDS, PARTLY, FAILS, UNTESTABLE, MISSING)


@dataclass(frozen=True)
class Row:
    """One row of the report."""
    claim: str
    published: str
    ours: str
    verdict: str
    why: str
    source: str = ""  # the experiment the row reads


@dataclass(frozen=True)
class AtLeast:
    """The verdict of a number where more is better: *holds* at ``holds``
    or more, *partly* at ``partly`` or more (when given), else *does not
    hold*.  NaN does not hold."""
    holds: float
    partly: float = None

    def __call__(self, value):
        if value >= self.holds:
            return HOLDS
        return PARTLY if self.partly is not None and value >= self.partly else FAILS


@dataclass(frozen=True)
class AtMost:
    """The verdict of a number where less is better: *holds* at ``holds``
    or less, *partly* at ``partly`` or less (when given), else *does not
    hold*.  NaN does not hold."""
    holds: float
    partly: float = None

    def __call__(self, value):
        if value <= self.holds:
            return HOLDS
        return PARTLY if self.partly is not None and value <= self.partly else FAILS


@dataclass(frozen=True)
class Share:
    """The verdict of a count of cases that agree with the claim: *holds*
    when at least ``holds`` of them do (a fraction; 1.0: all), *partly* when
    at least one does, else *does not hold*; no case at all is *not measured
    yet*."""
    holds: float = 1.0

    def __call__(self, agree, cases):
        if not cases:
            return MISSING
        return HOLDS if agree >= self.holds * cases else PARTLY if agree else FAILS


@dataclass(frozen=True)
class Needs:
    """What a claim needs that this machine or scale may lack (16 physical
    cores, a GPU, the paper's sizes) and the command that judges it where
    that is at hand; a row *not testable on this machine* names both.
    Without a command, the harness cannot judge it anywhere yet."""
    what: str  # "a machine with 16+ physical cores", "the paper scale's 1e8 points"
    command: str = ""

    def __str__(self):
        if not self.command:
            return f"needs {self.what}; no command of the harness judges it yet"
        return f"needs {self.what}: `{self.command}`"


@dataclass(frozen=True)
class Claim:
    """A published statement and how an experiment judges it.

    ``judge(claim, results)`` returns the claim's rows (a Row, or a list of
    them), built with ``claim.row`` and ``claim.missing``; ``rule`` is its
    verdict rule (AtLeast, AtMost, Share, or None where the rule is in the
    judge) and ``limits`` any further thresholds it reads, by name."""
    text: str
    published: str
    judge: Callable
    rule: Callable = None
    limits: dict = field(default_factory=dict)
    # what judging it needs where this machine or scale falls short (Needs):
    # its *not testable on this machine* rows name the command to run there
    needs: Needs = None

    def row(self, ours, verdict, why, text=None, published=None):
        return Row(text or self.text, published or self.published, ours, verdict, why)

    def missing(self, why=""):
        """A *not measured yet* row; without ``why`` the report names the
        command that measures it."""
        return Row(self.text, self.published, "-", MISSING, why)


class Results:
    """The stored results under one root, loaded once per experiment."""

    def __init__(self, root):
        self.root = Path(root)
        self._frames = {}

    def frame(self, name):
        """The experiment's results, or None when it has none (no file, or
        no rows)."""
        if name not in self._frames:
            path = self.root / name / "results.csv"
            df = results.load(path.parent) if path.exists() else None
            self._frames[name] = None if df is None or df.empty else df
        return self._frames[name]

    def summary(self, name, by=results.CELL, regime="loop"):
        """The experiment's cells summarized (results.summarize), in one
        regime (drivers.isolate.REGIMES; the papers' steady state by
        default), or None."""
        df = self.frame(name)
        if df is None:
            return None
        return results.summarize(df[df["regime"] == regime], by=by)

    def meta(self, name):
        return results.metadata(self.root, name)


def judge(experiment, res):
    """The rows of every claim ``experiment`` declares, judged on ``res``:
    each claim reads as not measured yet (naming the command) while the
    experiment has no results."""
    rows = []
    for claim in experiment.claims:
        got = claim.missing() if res.frame(experiment.name) is None else claim.judge(claim, res)
        for row in [got] if isinstance(got, Row) else got:
            if row.verdict == MISSING and not row.why:
                row = replace(row, why=f"run `{experiment.command}`")
            if row.verdict == UNTESTABLE and claim.needs:
                row = replace(row, why="; ".join(w for w in (row.why, str(claim.needs)) if w))
            rows.append(replace(row, source=row.source or experiment.name))
    return rows
