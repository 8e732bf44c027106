"""The stability verdicts of two restpose binaries compared on the Pinocchio, pybullet and wheels
corpora (the cases of scripts/{pinocchio,pybullet,wheels}_corpus.py, analyze --load-steps 1):
prints every row whose termination, iterations, verdict or energy differ, each binary's
(termination, iterations, verdict, energy, smallest listed eigenvalue, tolerance, gradient
norm). Usage, with the peers venv's python: verdict_diff.py BIN_A BIN_B"""
import glob, json, os, subprocess, sys, tempfile
V = os.path.expanduser('~/.cache/restpose-peers/venv')
os.environ['ERD_ROBOTS'] = glob.glob(V + '/lib/python*/site-packages/cmeel.prefix/share/example-robot-data/robots')[0]
import pybullet_data
os.environ['PYBULLET_DATA'] = pybullet_data.getDataPath()
os.environ['RESTPOSE'] = 'x'
SITE = glob.glob(V + '/lib/python*/site-packages')[0]
os.environ['RTB_DATA'] = SITE + '/rtbdata'
os.environ['ICUB_MODELS'] = V + '/share/iCub'
os.environ['GYM_IGNITION_MODELS'] = SITE + '/gym_ignition_models'
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pinocchio_corpus as pc, pybullet_corpus as pb, wheels_corpus as wc

def run(b, urdf, extra):
    with tempfile.TemporaryDirectory() as t:
        out = t + '/r.json'
        subprocess.run([b, 'analyze', '-q', urdf, '--load-steps', '1', '--json', out] + extra,
                       capture_output=True, timeout=300)
        if not os.path.exists(out):
            return None
        d = json.load(open(out))
    s = d.get('stability') or {}
    ev = s.get('eigenvalues') or [None]
    return (d['termination'], d['iterations'], s.get('verdict'), round(d['potential_energy'], 9),
            ev[0], s.get('tolerance'), d['diagnostics']['gradient_norm'])

def cases(tmp):
    for name, f, _, extra in pc.cases():
        yield 'erd ' + name, f, extra
    for group, name, f, _, extra, _ in pb.cases(tmp):
        yield 'pyb ' + name, f, extra
    for group, root, paths, options, geometry in wc.sets():
        for p in paths:
            yield 'wheels ' + os.path.relpath(p, root), p, options

bins = sys.argv[1:]
n = changed = 0
with tempfile.TemporaryDirectory() as tmp:
    for name, f, extra in cases(tmp):
        r = [run(b, f, extra) for b in bins]
        n += 1
        if len({str(x[:4]) if x else 'None' for x in r}) > 1:
            changed += 1
            print(name, *r, sep='\n    ', flush=True)
print(f'{n} rows, {changed} differ')
