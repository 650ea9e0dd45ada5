"""Weight drift under pair STDP in cerebx and in NEST's ``stdp_synapse``, compared synapse by synapse.

Both compute the same rule once cerebx's ``pair_stdp`` has ``delay: dendritic`` (:mod:`cerebx.export.mapping`), but
they hold its state differently at a run's end:

- cerebx updates a weight at every event as it reaches the synapse: at cerebx time T it has applied every pre
  spike emitted before T − d (its arrival is before T) and every post spike that reached the synapse (t_post + d)
  before T − d (a post spike reaches the synapse one delay after it happened, and pairs with arrivals one more
  delay later; :mod:`cerebx.snn.learning`).
- NEST updates a weight only when a pre spike passes (it then applies the potentiation of the post spikes since
  the last one, then the depression); its weight recorder holds the weight each pre spike transmitted.

:func:`nest_weights_at` therefore takes NEST's weight at its last pre spike before T − d and applies NEST's
potentiation for the post spikes that reached the synapse since then and before T − d, with NEST's own spikes
and parameters: the state cerebx holds at T, computed from what NEST computed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

EPS_MS = 1e-6


def _facilitate(w: float, w_max: float, lam: float, mu_plus: float, kplus: float) -> float:
    x = w / w_max
    return min(x + lam * (1.0 - x) ** mu_plus * kplus, 1.0) * w_max


def nest_weights_at(out: dict[str, np.ndarray], name: str, w0: dict[tuple[int, int, float], float],
                    pre_spikes: tuple[np.ndarray, np.ndarray], post_spikes: tuple[np.ndarray, np.ndarray],
                    params: dict[str, float], ms: float) -> dict[tuple[int, int, float], float]:
    """Projection ``name``'s weights as cerebx holds them at cerebx time ``ms``, from a NEST run (``out``: the
    arrays ``nest_network.py --weights`` wrote; ``w0``: initial weight per (pre, post, delay); ``pre_spikes``,
    ``post_spikes``: NEST's (local index, time) of the two populations; ``params``: the stdp_synapse's)."""
    lam, mu_plus, tau_plus, w_max = params["lambda"], params["mu_plus"], params["tau_plus"], abs(params["Wmax"])
    pre_i, pre_t = pre_spikes
    post_i, post_t = post_spikes
    pre_by = {int(j): np.sort(pre_t[pre_i == j]) for j in np.unique(pre_i)}
    post_by = {int(i): np.sort(post_t[post_i == i]) for i in np.unique(post_i)}
    wr_pre, wr_post, wr_t, wr_w = (out[f"wr/{name}/{k}"] for k in ("pre", "post", "t", "w"))
    order = np.lexsort((wr_t, wr_post, wr_pre))
    wr_pre, wr_post, wr_t, wr_w = wr_pre[order], wr_post[order], wr_t[order], np.abs(wr_w[order])
    keys = wr_pre.astype(np.int64) * (1 << 32) + wr_post
    none = np.zeros(0)
    result = {}
    for (j, i, d), w_init in w0.items():
        cut = ms - d
        a, b = np.searchsorted(keys, j * (1 << 32) + i, "left"), np.searchsorted(keys, j * (1 << 32) + i, "right")
        t_ev, w_ev = wr_t[a:b], wr_w[a:b]
        n = int(np.searchsorted(t_ev, cut - EPS_MS))
        if n == 0:
            result[(j, i, d)] = w_init  # no pre spike yet: no pairing either
            continue
        w, t_last = float(w_ev[n - 1]), float(t_ev[n - 1])
        pre = pre_by.get(j, none)
        pre = pre[pre <= t_last + EPS_MS]
        kplus = float(np.exp(-(t_last - pre) / tau_plus).sum())
        for p in post_by.get(i, none):
            if t_last + EPS_MS < p + d < cut - EPS_MS:
                w = _facilitate(w, w_max, lam, mu_plus, kplus * np.exp((t_last - (p + d)) / tau_plus))
        result[(j, i, d)] = w
    return result


@dataclass
class Drift:
    """One plastic projection's weight drift over a run, cerebx against NEST (nS)."""

    projection: str
    synapses: int
    w0_mean: float
    drift_cerebx: float  # mean change of the weights
    drift_nest: float
    drift_diff: float  # (nest - cerebx) / |cerebx| of the mean change
    drift_corr: float  # correlation of the per-synapse changes
    max_abs_diff: float  # largest |w_cerebx - w_nest| over the synapses
    exact: float  # synapses within 1e-6 of the weight bound of each other


def drift_row(name: str, w0: np.ndarray, w_cerebx: np.ndarray, w_nest: np.ndarray, w_max: float) -> Drift:
    """Compare cerebx's final weights with NEST's (nS, both in synapse table order; ``w0`` the initial ones)."""
    dc, dn = w_cerebx.astype(np.float64) - w0, w_nest - w0
    diff = np.abs(w_cerebx - w_nest)
    corr = float(np.corrcoef(dc, dn)[0, 1]) if dc.std() > 0 and dn.std() > 0 else float("nan")
    mc, mn = float(dc.mean()), float(dn.mean())
    return Drift(name, len(w0), float(w0.mean()), mc, mn, (mn - mc) / abs(mc) if mc else float("nan"), corr,
                 float(diff.max()) if len(diff) else 0.0, float(np.mean(diff <= 1e-6 * w_max)))


def drift_table(rows: list[Drift]) -> str:
    """The rows as a Markdown table."""
    lines = ["| projection | synapses | w0 (nS) | drift cerebx (nS) | drift NEST (nS) | drift diff | per-synapse corr. "
             "| max abs diff (nS) | equal (1e-6 W) |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r.projection} | {r.synapses:,} | {r.w0_mean:.4f} | {r.drift_cerebx:+.3e} | "
                     f"{r.drift_nest:+.3e} | {100 * r.drift_diff:+.3f} % | {r.drift_corr:.4f} | {r.max_abs_diff:.2e} | "
                     f"{100 * r.exact:.1f} % |")
    return "\n".join(lines)
