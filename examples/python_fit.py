"""sepval from Python: simulate two releases, fit the 17 factors, diagnose what the model still
gets wrong, predict a release not flown, and plot it all with matplotlib when it is installed.

    pip install ./python              # from a clone, with a Rust toolchain
    pip install pandas matplotlib     # optional: DataFrames and figures
    python examples/python_fit.py [OUT_DIR]

Everything runs in this process (no worker executables); about a minute on 2 cores. The outputs
(result.json, diagnosis.json, prediction.json, the CLI's figures and pages, and this script's
python_fit.png) go to OUT_DIR (default: python-fit-out).
"""

import shutil
import sys
from pathlib import Path

import sepval


def releases():
    """Two noisy releases of the default store at two flight conditions, made by the
    simulator with a sideslip effect the baseline model lacks (the truth to find)."""
    made = []
    for seed, (mach, beta) in enumerate([(0.8, 3.0), (0.9, -4.0)], start=1):
        s = sepval.scenario()
        s["flight"].update(mach=mach, beta_deg=beta)
        made.append(sepval.simulate(scenario=s, effects={"roll_due_to_sideslip": -0.05}, noise_seed=seed))
    return made


def show_progress(event):
    """One line per stage, and the goals every tenth step."""
    if event["event"] == "start":
        print(f"  {event['stage']} ...", flush=True)
    elif event["event"] == "step" and event["step"] % 10 == 0 and event["j_pos_m"] is not None:
        print(f"    step {event['step']}: J_pos {event['j_pos_m']:.4f} m, J_att {event['j_att_deg']:.3f} deg", flush=True)


def plot(data, prediction, out):
    """The releases fitted and the prediction's bands (skipped without matplotlib)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no figure (pip install matplotlib)")
        return
    fig, (ax_z, ax_roll) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for k, d in enumerate(data):
        label = f"release {k + 1} (Mach {d.attrs['mach']}, beta {d.attrs['beta_deg']} deg)"
        ax_z.plot(d["t_s"], d["z_m"], ".", ms=2, label=label)
        ax_roll.plot(d["t_s"], d["roll_deg"], ".", ms=2, label=label)
    b = prediction.bands
    for ax, channel in ((ax_z, "z_m"), (ax_roll, "roll_deg")):
        ax.fill_between(b["t_s"], b[f"{channel}_lo"], b[f"{channel}_hi"], alpha=0.3, label="predicted, 95 % band")
        ax.plot(b["t_s"], b[f"{channel}_mid"], "k-", lw=1)
        ax.set_xlabel("t [s]")
        ax.set_ylabel(channel)
    ax_z.legend(fontsize=7)
    fig.suptitle(f"Prediction at Mach {prediction.condition['mach']}, beta {prediction.condition['beta_deg']} deg")
    fig.savefig(out / "python_fit.png", dpi=120)
    print(f"figure:    {out / 'python_fit.png'}")


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "python-fit-out")
    if out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True)
    data = releases()
    print("fit (GA, then Levenberg-Marquardt):")
    fit = sepval.fit(data, generations=60, seed=1, out=out / "fit", progress=show_progress)
    print(f"fit:       J_pos {fit.j_pos_m:.4f} m, J_att {fit.j_att_deg:.3f} deg (noise {fit.sigma_pos_m:.4f} m)")
    print(f"           fwdfac = {fit.factors['fwdfac']:.3f} +- {fit.std_errors['fwdfac']:.3f}")
    for pair in fit.identifiability["compensating"][:3]:
        print(f"           {pair['a']} and {pair['b']} compensate each other (rho {pair['rho']:+.2f})")
    print("diagnose:")
    diagnosis = sepval.diagnose(data, generations=30, out=out / "diagnose", progress=show_progress)
    print(f"verdict:   {diagnosis.verdict}")
    for cause in diagnosis.causes:
        print(f"cause:     {cause}: {diagnosis.parameters[cause]}")
    condition = sepval.scenario()
    condition["flight"].update(mach=0.85, beta_deg=-1.0)
    prediction = sepval.predict(diagnosis, scenario=condition, samples=300, out=out / "predict")
    print(f"predict:   at Mach 0.85, beta -1 deg; band shares {prediction.sources} (most: {prediction.dominant})")
    plot(data, prediction, out)
    print(f"reports:   {diagnosis.out / 'report.html'}, {prediction.out / 'report.html'}")


if __name__ == "__main__":
    main()
