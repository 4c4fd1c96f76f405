"""pm4py's inductive miner on a robot type's traces, with its two costliest steps done faster.

The tree is the one pm4py's public ``discover_process_tree_inductive`` gives on the same
traces as a log (``tests/discovery/test_inductive_route.py`` compares them), so the model does
not depend on this module. Where the miner spends its time on logs whose traces are all
distinct (robots interleaving their steps freely), three steps are done here more directly,
with the same result, object for object:

- the directly-follows graph of a sub-log, which pm4py builds with a ``Counter.update`` per
  pair and a pass over the log per activity for the start and end activities;
- the concurrency cut's projection, which pm4py makes with a pass over the log per group,
  filtering every trace through a lambda; here each trace is walked once and its steps dealt
  to their groups;
- the exclusive-choice cut's connected components, which pm4py finds through a networkx
  graph, its undirected copy and a copy of each component; here by union-find over the
  pairs;
- the folding of the mined tree, which pm4py's ``fold`` starts with a deep copy of the tree
  (and again at each round); the miner's tree is this module's own, so it is folded in
  place, by pm4py's own steps.

Everything else (the cuts' search, the other projections, base cases, fall-throughs, the noise
filter) is pm4py's own. Only this module imports pm4py at its top: it costs 2 s and prints a
banner, so the collaboration imports this module when it mines.
"""

from __future__ import annotations

import itertools
from collections import Counter
from collections.abc import Collection, Sequence
from typing import Any

from pm4py.algo.discovery.inductive.cuts.concurrency import ConcurrencyCutUVCL
from pm4py.algo.discovery.inductive.cuts.factory import CutFactory
from pm4py.algo.discovery.inductive.cuts.xor import ExclusiveChoiceCutUVCL
from pm4py.algo.discovery.inductive.dtypes.im_ds import IMDataStructureUVCL
from pm4py.algo.discovery.inductive.variants.im import IMUVCL
from pm4py.algo.discovery.inductive.variants.imf import IMFUVCL
from pm4py.objects.dfg.obj import DFG
from pm4py.objects.process_tree.obj import ProcessTree
from pm4py.objects.process_tree.utils.generic import _fold, reduce_tau_leafs, tree_sort
from pm4py.util import constants

#: a log as pm4py's miner reads it: each distinct trace and how many cases followed it
Variants = Counter  # Counter[tuple[str, ...]]


def inductive_tree(traces: Sequence[Sequence[str]], noise: float) -> ProcessTree:
    """pm4py's inductive miner (IMf with a noise threshold) on ``traces``, given the variant
    counter pm4py builds from a DataFrame, without building one: the cases in the order pm4py
    sorts their ids (as text), so the tree is the one its DataFrame route gives."""
    order = sorted((number for number, trace in enumerate(traces) if trace), key=str)
    variants = Counter(tuple(traces[number]) for number in order)
    parameters = {
        "noise_threshold": noise,
        "multiprocessing": constants.ENABLE_MULTIPROCESSING_DEFAULT,
        "disable_fallthroughs": False,
    }
    miner = _IMf(parameters) if noise > 0 else _IM(parameters)
    tree = _folded(miner.apply(_sub_log(variants), parameters))
    tree_sort(tree)
    return tree


def _folded(tree: ProcessTree) -> ProcessTree:
    """pm4py's ``fold`` (``pm4py.objects.process_tree.utils.generic``) step by step, without
    its deep copy of the tree at each round: the tree is ours and not kept unfolded."""
    tree = _fold(tree)
    root = tree
    while root.parent is None and len(tree.children) == 1:
        root = tree.children[0]
        root.parent = None
        tree.children.clear()
        tree = root
    text = str(tree)
    tree = reduce_tau_leafs(tree)
    if len(str(tree)) != len(text):
        tree = _folded(tree)
        text = str(tree)
    again = _fold(tree)
    if len(str(again)) != len(text):
        tree = _folded(again)
    return tree


def directly_follows(variants: Variants) -> DFG:
    """The directly-follows graph pm4py's miner keeps beside a sub-log: the same counts, the
    pairs in the order they first occur, start and end activities in name order."""
    dfg = DFG()
    graph = dfg.graph
    starts: Counter[str] = Counter()
    ends: Counter[str] = Counter()
    for trace, cases in variants.items():
        if not trace:
            continue
        for pair in itertools.pairwise(trace):
            graph[pair] += cases
        starts[trace[0]] += cases
        ends[trace[-1]] += cases
    dfg.start_activities.update({name: starts[name] for name in sorted(starts)})
    dfg.end_activities.update({name: ends[name] for name in sorted(ends)})
    return dfg


def _sub_log(variants: Variants) -> IMDataStructureUVCL:
    return IMDataStructureUVCL(variants, directly_follows(variants))


class _OnePassConcurrency(ConcurrencyCutUVCL):
    """pm4py's concurrency cut, its projection made in one pass over the log."""

    @classmethod
    def project(
        cls,
        obj: IMDataStructureUVCL,
        groups: list[Collection[Any]],
        parameters: dict[str, Any] | None = None,
    ) -> list[IMDataStructureUVCL]:
        group_of = {activity: number for number, group in enumerate(groups) for activity in group}
        projected: list[list[tuple[str, ...]]] = [[] for _ in groups]  # each group's traces
        for trace in obj.data_structure:
            parts: list[list[str]] = [[] for _ in groups]
            for activity in trace:
                number = group_of.get(activity)
                if number is not None:  # pm4py's filter drops what no group holds
                    parts[number].append(activity)
            for traces, part in zip(projected, parts, strict=True):
                traces.append(tuple(part))
        return [_sub_log(_counted(traces, obj.data_structure)) for traces in projected]


def _counted(traces: list[tuple[str, ...]], variants: Variants) -> Variants:
    """The projected ``traces`` (one per variant of ``variants``, in its order) counted as
    the variants' cases: each distinct trace in the order it first comes."""
    cases = variants.values()
    if all(count == 1 for count in cases):  # the usual log: each variant once
        return Counter(traces)
    log: Variants = Counter()
    for trace, count in zip(traces, cases, strict=True):
        log[trace] += count
    return log


class _UnionFindExclusiveChoice(ExclusiveChoiceCutUVCL):
    """pm4py's exclusive-choice cut, the directly-follows graph's connected components
    found by union-find over its pairs rather than through a networkx graph, its undirected
    copy and a copy of each component; the groups in pm4py's order."""

    @classmethod
    def holds(
        cls, obj: IMDataStructureUVCL, parameters: dict[str, Any] | None = None
    ) -> list[Collection[Any]] | None:
        dfg = obj.dfg
        parent = {
            activity: activity
            for activity in itertools.chain(
                itertools.chain.from_iterable(dfg.graph), dfg.start_activities, dfg.end_activities
            )
        }

        def root(activity: Any) -> Any:
            while parent[activity] != activity:
                parent[activity] = parent[parent[activity]]
                activity = parent[activity]
            return activity

        for first, second in dfg.graph:
            parent[root(first)] = root(second)
        groups: dict[Any, set[Any]] = {}
        for activity in parent:
            groups.setdefault(root(activity), set()).add(activity)
        if len(groups) < 2:
            return None
        # as pm4py orders them: the projection breaks ties by a group's place
        return sorted(groups.values(), key=lambda group: sorted(map(str, group)))


#: pm4py's cuts replaced here by the same cut done faster
_FASTER = {
    ConcurrencyCutUVCL: _OnePassConcurrency,
    ExclusiveChoiceCutUVCL: _UnionFindExclusiveChoice,
}


class _FasterCuts:
    """The miner's cut search as pm4py's (the same cuts in the same order), with the cuts of
    :data:`_FASTER` replaced."""

    def find_cut(self, obj: IMDataStructureUVCL, parameters: dict[str, Any] | None = None):
        for cut in CutFactory.get_cuts(obj, self.instance(), parameters):  # type: ignore[attr-defined]
            found = _FASTER.get(cut, cut).apply(obj, parameters)
            if found is not None:
                return found
        return None


class _IM(_FasterCuts, IMUVCL):
    pass


class _IMf(_FasterCuts, IMFUVCL):
    pass
