# %% [markdown]
# # The paper's two-shaft model from Python
#
# Bauer, Haslinger, Offner, Parikyan (RICAM 2021-43): a gear on a shaft with a rectangular
# mesh stiffness (one- and two-tooth contact), the fundamental the mesh frequency. Run from
# the repository's root: `python python/examples/two_shaft.py [--out DIR]`. Each `# %%` cell
# runs on its own in a notebook too.

# %%
import argparse
import os

import numpy as np

import hbal

parser = argparse.ArgumentParser()
parser.add_argument("--out", default="out/python_two_shaft")
args, _ = parser.parse_known_args()
os.makedirs(args.out, exist_ok=True)

scene = hbal.Scene.load("examples/scenes/two_shaft_6000rpm.toml")
print(scene, "|", scene.speed, scene.speed_unit, "| H =", scene.harmonics)

# %% One solve: converged, its error estimate, its stability, the mesh's outputs.
result = hbal.solve(scene)
print(f"converged {result.converged}, error estimate {result.error_estimate:.1e}, stable {result.stable}, "
      f"max |mu| = {np.abs(result.multipliers).max():.4f}")
mesh = result.element("mesh")
print(f"mesh deflection {mesh['coordinate']['min']:.3e} .. {mesh['coordinate']['max']:.3e} m, "
      f"force {mesh['force']['min']:.2f} .. {mesh['force']['max']:.2f} N")
print(result.to_pandas().head(6).to_string(index=False))

# %% The time series over one mesh period.
t, q = result.time_series(512)
print(f"gear angle over a period: {q[0].min():.4e} .. {q[0].max():.4e} (max |q| reported {result.max_abs[0]:.4e})")

# %% The same model from matrices: one DOF, the mesh element, the paper's loads.
doc = scene.to_dict()
from_matrices = hbal.scene_from_matrices(
    doc["dofs"], np.array(doc["mass"]), elements=doc["elements"], loads=doc["loads"],
    fundamental=doc["fundamental"], harmonics=doc["harmonics"], solver=doc.get("solver"),
)
again = hbal.solve(from_matrices)
print("from matrices, same harmonics:", np.array_equal(again.harmonics, result.harmonics))

# %% A run-up from 3000 to 9000 rpm with stability, and its order cuts.
branch = hbal.sweep(scene, 9000, start=3000)
print(f"{len(branch.points)} points, reached {branch.reached}, {int(np.sum(branch.stable == 0))} unstable")
for order in (4, 8, 12):
    cut = branch.order_cut("gear", order)
    i = int(np.argmax(cut))
    print(f"  order {order}: peak {cut[i]:.3e} at {branch.speed[i]:.0f} rpm")
branch.to_pandas().to_csv(os.path.join(args.out, "branch.csv"), index=False)

# %% A parameter study: the two-tooth stiffness +-10 %, percentile bands of the mesh orders.
from hbal import study, variants

spread = variants.around(scene, {"elements[0].profile.two_tooth": 0.1, "elements[0].profile.one_tooth": 0.1})
table = study.run(scene, variants.latin_hypercube(spread, 40, seed=1), speeds=np.arange(3000, 9001, 500),
                  quantities=["u(mesh)"], orders=[4, 8])
print(hbal.percentile_bands(table, "u(mesh)", 4).round(9).head().to_string())
try:
    hbal.plot_bands(table, "u(mesh)", [4, 8], os.path.join(args.out, "bands.svg"), unit="rpm")
    print("wrote", os.path.join(args.out, "bands.svg"))
except ImportError:
    print("matplotlib is not installed: no plot")
