"""
Which rebound a compliant law gives
===================================

The founding paper's Hyster-Hertz law (Lankarani-Nikravesh) does not rebound two free
bodies at its restitution ``e``: its rebound ratio never falls below about 0.663. The
``"hertz-damped"`` law solves for its damping so that the rebound is exactly ``e``.
:attr:`vibroimpact.Contact.effective_restitution` gives each law's two-body rebound ratio.
"""

import warnings

import matplotlib.pyplot as plt
import numpy as np

import vibroimpact as vi

targets = np.linspace(0.05, 1.0, 40)
rebound = {}
for law in ("hyster-hertz", "hertz-damped"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", vi.RestitutionWarning)  # hyster-hertz warns below 0.7
        rebound[law] = [
            vi.Contact(law, stiffness=1e6, restitution=e).effective_restitution for e in targets
        ]

fig, ax = plt.subplots(figsize=(6, 4))
for law, values in rebound.items():
    ax.plot(targets, values, label=law)
ax.plot(targets, targets, "k--", lw=0.8, label="rebound = e")
ax.set_xlabel("the law's restitution e")
ax.set_ylabel("two-body rebound ratio")
ax.legend()
plt.show()
