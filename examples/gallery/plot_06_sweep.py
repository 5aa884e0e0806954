"""
A parameter sweep with a Monte Carlo at each point
==================================================

The ``shipgnc sweep`` command's engine, in process: a :class:`~shipgnc.study.spec.Study` of the
built-in scenario ``boat-autopilot`` over three reference-model bandwidths ``omega_ref`` of the
autopilot, each with 16 boats starting at random headings (seeded; member *i*'s draws do not
depend on how the study is chunked). ``run_study(..., client=dask.distributed.Client(...))`` runs
the same study on a cluster; here it runs in this process.

The box plots show the heading RMSE, which carries the members' spread (their start headings).
The settling time would show none: the autopilot makes the heading follow its reference model
(bandwidth ``omega_ref``), so every member settles after the 45° step at 10 s at the reference
model's own time, long after its start heading has been corrected.
"""

import matplotlib.pyplot as plt

from shipgnc.study.execute import run_study
from shipgnc.study.spec import Perturbation, Study, parse_grid
from shipgnc.viz.style import show_example

study = Study("boat-autopilot", grid=(parse_grid("controller.omega_ref=0.5,1,2"),), members=16, seed=1,
              perturb=(Perturbation.parse("psi_deg=uniform:-30,30"),),
              overrides=("simulation.t_end=30",))
ds = run_study(study, chunk_size=16).dataset
print(ds["heading_rmse_deg"].dims)                 # ('controller.omega_ref', 'member')

fig, ax = plt.subplots(figsize=(6, 3.8))
omega = ds["controller.omega_ref"].values
ax.boxplot([ds["heading_rmse_deg"].sel({"controller.omega_ref": w}).values for w in omega],
           positions=range(len(omega)))
ax.set_xticks(range(len(omega)), [f"{w:g}" for w in omega])
ax.set(xlabel="reference-model bandwidth ω_ref [rad/s]", ylabel="heading RMSE [deg]",
       title="boat-autopilot: 16 boats per grid point, start heading ±30°")
print("settling time [s] per ω_ref (every member alike):",
      ds["settling_time_s"].min("member").values, ds["settling_time_s"].max("member").values)
fig.tight_layout()
show_example()   # run as a script: saves the figure (and shows it where there is a display)
