import sys, time, os
import numpy as np
from mlc.scene import load_scene
from mlc.sim.integrator import Simulation, SimOptions
sc = load_scene(sys.argv[1]); scheme=sys.argv[2]; dt=float(sys.argv[3]); T=float(sys.argv[4]); acc=float(sys.argv[5]); chunk=float(sys.argv[6])
row = os.environ.get("ROW","11")
kw = eval(os.environ.get("KW","{}"))
drives = {k:int(c) for k,c in zip(sc.inputs,row)}
sim = Simulation(sc, drives, SimOptions(scheme=scheme, dt=dt, kT=float(os.environ.get("KT","1e-5")), seed=int(os.environ.get("SEED","0")), disp_acc=acc, **kw))
if os.environ.get("NOSTOPS"): sim.sp_k[sim.sp_tol > 0.2] = 1e-9
names=[p.name for p in sc.probes if p.name.startswith("dof")]
tt=0; W=0
while tt < T - 1e-9:
    t=time.perf_counter(); r = sim.run(chunk, record_interval=chunk, quiet=True); w=time.perf_counter()-t; W+=w; tt+=chunk
    f = getattr(sim._implicit,'factorisations',0) if sim._implicit else 0
    print("t %5.0f wall %6.1f total %6.1f evals %6d fact %5d | "%(tt, w, W, r.force_evals, f) + " ".join("%.3f"%r.probes[n][-1] for n in names), flush=True)
np.save(os.environ.get("OUT","/tmp/r12/last.npy"), np.array([r.probes[n][-1] for n in names]))
