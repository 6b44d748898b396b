# Copyright 2026 The ttb_sim Authors
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
The ``ttb-sim`` command line: argument parsing and the mapping of errors to exit codes.

The verbs themselves live in :mod:`ttb_sim.commands` (ROS-free, callable from
tests and the node).

Exit codes: 0 success; 1 numerical failure (divergence) or failed validation;
2 bad scenario or argument; 130 / 143 interrupted by SIGINT / SIGTERM. Every
refusal, a usage error of the argument parser included, is one line on stderr
starting ``ttb-sim: error:``.
"""

from __future__ import annotations

import argparse
import errno
import logging
import os
from pathlib import Path
import re
import sys
import threading
from typing import Any, NoReturn, Sequence

from ttb_sim import __version__
from ttb_sim.commands.signals import SignalHandlers, stop_now
from ttb_sim.config.loader import DEFAULT_SCENARIO
from ttb_sim.errors import ModelError, ScenarioError, TtbSimError

log = logging.getLogger('ttb_sim')

EXIT_OK, EXIT_FAILURE, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130


MAX_MESSAGE = 600
"""Longest error line printed (characters): a library's message may quote a long value."""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line (exit 2), as every other refusal."""

    def error(self, message: str) -> NoReturn:
        """Print the problem and where help is, on one line, and exit 2."""
        text = one_line(f'{message}; see `{self.prog} --help`')
        self.exit(EXIT_USAGE, f'ttb-sim: error: {text}\n')


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog='ttb-sim', description='Train-track-bridge dynamics: run scenarios '
                'offline to rosbag2, validate the physics, analyse bags, sweep speeds and '
                'seeds.')
    p.add_argument('--version', action='version', version=f'%(prog)s {__version__}')
    p.add_argument('-v', '--verbose', action='store_true', help='log progress details')
    sub = p.add_subparsers(dest='command', required=True, metavar='COMMAND')
    _add_model_verbs(sub)
    _add_bag_verbs(sub)
    return p


def _add_model_verbs(sub: Any) -> None:
    """Add the verbs that build a scenario's model: run, validate, bench, modes, frf."""
    run = sub.add_parser('run', help='simulate a scenario and record a rosbag2')
    run.add_argument('scenario', nargs='?', default=DEFAULT_SCENARIO,
                     help='YAML path or built-in name (see `ttb-sim scenarios`; default '
                          f'{DEFAULT_SCENARIO}: the coupled model with piles and soil)')
    # A str, not a Path: Path('') is '.', and an empty --out must be named as empty.
    run.add_argument('--out', help='bag directory to create (default: a new '
                     'folder under ./runs/)')
    run.add_argument('--speed-kmh', type=float, help='override train.speed_kmh')
    run.add_argument('--duration', type=float, help='override solver.duration (s)')
    run.add_argument('--storage', default='mcap', choices=('mcap', 'sqlite3'),
                     help='rosbag2 storage (default mcap)')
    run.add_argument('--set', dest='overrides', action='append', default=[],
                     metavar='KEY=VALUE', help='override a scenario key (YAML scalar); '
                     'repeatable')
    run.add_argument('--force', action='store_true', help='run even when the plan exceeds '
                     'the step budget (2e7 time steps)')

    val = sub.add_parser('validate', help='run the validation suite and print a table')
    val.add_argument('cases', nargs='*', metavar='CASE', help='case ids (default: all)')
    val.add_argument('--list', action='store_true', help='list the cases and exit')

    be = sub.add_parser('bench', help='time the solver variants side by side and compare '
                        'their results with the reference variant')
    be.add_argument('scenarios', nargs='*', metavar='SCENARIO',
                    help='YAML paths or built-in names (default: ten_span_train; '
                    'paper_ttbi and paper_ttbcpsi for 0.05 s; single_pile, 5 Hz harmonic, '
                    'for 0.2 s; pile_harmonic for 0.02 s)')
    be.add_argument('--duration', type=float, help='simulated time of every scenario (s)')
    be.add_argument('--variants', help='comma-separated solver.variant values (default: all; '
                    'reference always runs, as the comparison base)')
    be.add_argument('--json', type=Path, metavar='FILE', help='also write the report as JSON')
    be.add_argument('--repeat', type=int, default=1, help='interleaved rounds; the fastest '
                    'run of each variant is kept (default 1)')
    be.add_argument('--in-process', action='store_true', help='run every variant in this '
                    'process (peak memory is then not per run)')
    be.add_argument('--set', dest='overrides', action='append', default=[],
                    metavar='KEY=VALUE', help='override a scenario key; repeatable')
    be.add_argument('--threads', metavar='N,M', help='comma-separated solver.threads counts, '
                    'e.g. 1,2: every variant runs at each, as its own row (default: the '
                    "scenario's own setting, auto, once; * marks an automatic choice)")

    mo = sub.add_parser('modes', help="natural modes of a scenario's bridge, track and piled "
                        'piers nearest a frequency')
    mo.add_argument('scenario', help='YAML path or built-in name')
    mo.add_argument('--around', type=float, default=5.0, metavar='HZ',
                    help='centre frequency (default 5 Hz)')
    mo.add_argument('--count', type=int, default=20, help='number of modes (default 20)')
    mo.add_argument('--set', dest='overrides', action='append', default=[],
                    metavar='KEY=VALUE', help='override a scenario key; repeatable')
    mo.add_argument('--json', type=Path, metavar='FILE', help='also write the modes as JSON')

    fr = sub.add_parser('frf', help='frequency response of a pile-soil substructure scenario '
                        '(steady harmonic receptances), and whether its mesh holds')
    fr.add_argument('scenario', help='YAML path or built-in name with load.type not none '
                    '(e.g. single_pile)')
    fr.add_argument('--freqs', default='1:10:1', help="Hz: comma-separated ('1,2,5') or "
                    'START:STOP:STEP (default 1:10:1)')
    fr.add_argument('--refine', action='store_true', help='also solve with every element size '
                    'halved and report the change')
    fr.add_argument('--pml', type=float, metavar='M', help='a perfectly matched layer of this '
                    "thickness around the block instead of the scenario's boundary")
    fr.add_argument('--solver', default='auto', help='complex sparse solver: auto (pardiso '
                    'if installed), pardiso, superlu')
    fr.add_argument('--set', dest='overrides', action='append', default=[],
                    metavar='KEY=VALUE', help='override a scenario key; repeatable')
    fr.add_argument('--json', type=Path, metavar='FILE', help='also write the receptances')
    fr.add_argument('--plot', type=Path, metavar='FILE', help='also draw them (PNG)')
    fr.add_argument('--at', default='load', help="load (default): the scenario's load and "
                    "pile head; master: the piled pier's ground seen from the cap's master "
                    '(6 x 6 dynamic stiffness), with the reduced substructure the time '
                    'stepping uses beside it')
    fr.add_argument('--no-reduced', dest='reduced', action='store_false', help='with --at '
                    'master: leave out the reduced substructure (its first build of a mesh '
                    'takes minutes; a refinement study of the mesh does not need it)')


def _add_bag_verbs(sub: Any) -> None:
    """Add analyze, recover and compare (they read bags), sweep (many runs) and scenarios."""
    an = sub.add_parser('analyze', help='figures, metrics.json and index.html from a bag')
    an.add_argument('bag', help='bag directory (metadata.yaml + .mcap/.db3) or storage file')
    an.add_argument('--out', type=Path, help='output folder (default: BAG/analysis)')
    an.add_argument('--modes-window', choices=('free', 'whole'), default='free',
                    help='records of the modes section (operational modal analysis of the '
                    "bag's accelerometers): 'free' the free vibration after the last axle has "
                    "left the bridge (default), 'whole' the whole record (ambient vibration)")

    re_ = sub.add_parser(
        'recover', help='rewrite a bag a killed run left (no metadata.yaml, MCAP without '
        'summary) as a new, closed bag', description='Read the storage file of a bag whose '
        'recording was killed (SIGKILL, power cut) up to its last complete MCAP chunk or '
        'SQLite 3 commit, and write those messages as a new bag of the same storage with a '
        'fresh metadata.yaml (summary.json copied if there is one). The original is only '
        'read. `ttb-sim analyze` reads such a bag directly too, with a warning. Exit 2 when '
        'nothing complete can be read back.')
    re_.add_argument('bag', help='bag directory or its .mcap / .db3 file')
    re_.add_argument('--out', help='new bag directory to create (default: BAG-recovered '
                     'beside the bag)')

    co = sub.add_parser('compare', help='the analysis figures of several bags overlaid, with a '
                        'table of differences')
    co.add_argument('bags', nargs='+', metavar='BAG', help='two or more bags')
    co.add_argument('--labels', help='comma-separated labels, one per bag (default: folder '
                    'names)')
    co.add_argument('--out', type=Path, help='output folder (default: a new folder under '
                    './runs/)')

    sw = sub.add_parser('sweep', help='run a scenario at several speeds and seeds in parallel '
                        '(local processes or a Dask cluster), with an aggregate table')
    sw.add_argument('scenario', help='YAML path or built-in name')
    sw.add_argument('--speeds-kmh', required=True, help='comma-separated speeds, e.g. '
                    '250,300,350,400')
    sw.add_argument('--seeds', type=int, help='irregularity seeds 1..N per speed (default: the '
                    "scenario's seed)")
    sw.add_argument('--set', dest='overrides', action='append', default=[],
                    metavar='KEY=VALUE', help='override a scenario key; repeatable')
    sw.add_argument('--duration', type=float, help='override solver.duration (s)')
    sw.add_argument('--storage', default='mcap', choices=('mcap', 'sqlite3'))
    sw.add_argument('--out', type=Path, help='sweep folder (default ./runs/sweep-NAME); a '
                    'rerun with the same folder skips finished cases')
    where = sw.add_mutually_exclusive_group()
    where.add_argument('--workers', type=int, help='local worker processes (default: the '
                       'number of cores, at most the number of cases)')
    where.add_argument('--scheduler', metavar='ADDRESS', help='Dask scheduler, e.g. '
                       "tcp://host:8786 (pip install 'ttb_sim[dask]')")
    sw.add_argument('--force', action='store_true', help='run cases above the step budget')

    ds = sub.add_parser('dataset', help='labelled passages drawn from priors over scenario '
                        'keys, as one Parquet table (docs/twin.md)')
    ds.add_argument('spec', help='dataset spec (YAML): scenario, n, sampler, seed, priors, ...')
    ds.add_argument('--out', type=Path, help='data-set folder (default ./runs/dataset-SPEC); a '
                    'rerun with the same folder skips finished cases')
    ds.add_argument('--n', type=int, help="number of cases (replaces the spec's n)")
    where = ds.add_mutually_exclusive_group()
    where.add_argument('--workers', type=int, help='local worker processes (default: the '
                       'number of cores, at most the number of cases)')
    where.add_argument('--scheduler', metavar='ADDRESS', help='Dask scheduler, e.g. '
                       "tcp://host:8786 (pip install 'ttb_sim[dask]')")
    ds.add_argument('--force', action='store_true', help='run cases above the step budget')

    idn = sub.add_parser('identify', help='Bayesian updating of scenario keys from a recorded '
                         'passage (emcee on a surrogate of the model; docs/twin.md)')
    idn.add_argument('bag', help='bag directory (its sensors/<name> topics are the data)')
    idn.add_argument('--param', dest='params', action='append', default=[],
                     metavar='KEY=FAMILY:A,B', help='a key to update and its prior: '
                     'uniform:A,B, normal:MEAN,SD or lognormal:MU,SIGMA; repeatable')
    idn.add_argument('--scenario', help="the model to update (default: the bag's own)")
    idn.add_argument('--set', dest='overrides', action='append', default=[],
                     metavar='KEY=VALUE', help='override a key of the model; repeatable')
    idn.add_argument('--out', type=Path, help='output folder (default: BAG/identify)')
    idn.add_argument('--sensors', help='comma-separated sensor names (default: every sensor '
                     'of the model recorded in the bag)')
    idn.add_argument('--design', type=int, default=0, help='forward runs of the surrogate '
                     '(default 8 d + 8)')
    idn.add_argument('--steps', type=int, default=3000, help='MCMC steps (default 3000)')
    idn.add_argument('--walkers', type=int, default=0, help='MCMC walkers (default max(16, 4 d))')
    idn.add_argument('--seed', type=int, default=0, help='seed of the design and the sampler')
    idn.add_argument('--discrepancy', type=float, default=0.02, help='model discrepancy in '
                     'log10 PSD (default 0.02, about 5 %%)')
    idn.add_argument('--response', default='passage', choices=('passage', 'ambient'),
                     help='what scatters in the data: the sensor noise over a deterministic '
                     'passage (default), or an ambient random response too')
    idn.add_argument('--fmin', type=float, help='lowest PSD frequency (default 1 / segment)')
    idn.add_argument('--fmax', type=float, help='highest (default 0.8 x the lowest sensor '
                     'Nyquist frequency)')
    idn.add_argument('--refine', type=int, default=0, metavar='N',
                     help='N more runs over the first posterior, then sample again (default 0)')
    idn.add_argument('--points', type=int, default=48, help='PSD grid points (default 48)')
    idn.add_argument('--segment', type=float, help='Welch segment, s (default min(2, record/4))')
    where = idn.add_mutually_exclusive_group()
    where.add_argument('--workers', type=int, help='local worker processes for the design runs '
                       '(default: the number of cores, at most the number of runs)')
    where.add_argument('--scheduler', metavar='ADDRESS', help='Dask scheduler, e.g. '
                       "tcp://host:8786 (pip install 'ttb_sim[dask]')")

    sc = sub.add_parser('scenarios', help='list the built-in scenarios')
    sc.add_argument('--keys', action='store_true',
                    help='list every scenario key with unit, default and range')


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    with SignalHandlers() as handlers:
        if threading.current_thread() is threading.main_thread():
            handlers.install(stop_now)
        return _main(argv)


def entry() -> None:
    """
    Run ``ttb-sim`` as a program (the console script and ``python -m ttb_sim.cli``).

    Unlike :func:`main`, the one-line SIGINT / SIGTERM handler stays installed until
    the process exits, so a signal that arrives after the verb has finished (its
    output is complete) still ends in one line and exit 128 + signal, never in a
    ``KeyboardInterrupt`` traceback during shutdown; and the process ends with
    ``os._exit`` once the verb has returned and the output is flushed.
    """
    if threading.current_thread() is threading.main_thread():
        SignalHandlers().install(stop_now)   # never restored: see above
    try:
        code = _main(sys.argv[1:])
    except SystemExit as exc:  # argparse's own exits (usage errors, --help)
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    # The verb has closed its files. Ending here skips the interpreter's finalisation, which
    # restores the default signal dispositions and then tears down the imported extension
    # modules (numba/LLVM, BLAS) for a second or more under load: a Ctrl-C in that window
    # used to kill the finished process by SIGINT (exit -2), hiding its exit code.
    logging.shutdown()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


def one_line(exc: BaseException | str) -> str:
    """
    Return an error's message on one line, cut to :data:`MAX_MESSAGE` characters.

    Line breaks (a library's text may span several lines) become spaces; other
    control characters, which a user value may carry into the message and a
    terminal may take for a line break (the record and Unicode line separators), are
    escaped as in ``repr``.
    """
    text = re.sub(r'\s*\n\s*', ' ', str(exc).strip())
    text = ''.join(c if c.isprintable() else repr(c)[1:-1] for c in text)
    if len(text) > MAX_MESSAGE:
        half = MAX_MESSAGE // 2
        text = f'{text[:half]}...{text[-half:]} ({len(text)} characters)'
    return text


_PATH_ERRORS = frozenset({errno.ENAMETOOLONG, errno.ENOENT, errno.ENOTDIR, errno.EISDIR,
                          errno.EACCES, errno.EPERM, errno.EROFS, errno.ELOOP, errno.EEXIST,
                          errno.EINVAL})
"""errno values that say a path given cannot be used: exit 2, like any bad argument."""


def _os_error(exc: OSError) -> int:
    """Print an OSError in one line (the files named); exit 2 for a bad path, else 1."""
    names = ' and '.join(repr(str(f)) for f in (exc.filename, exc.filename2) if f is not None)
    what = f'{names}: {exc.strerror or exc}' if names else str(exc.strerror or exc)
    if exc.errno in _PATH_ERRORS:
        print(f'ttb-sim: error: {one_line(what)}', file=sys.stderr)
        return EXIT_USAGE
    print(f'ttb-sim: failed: {one_line(what)}', file=sys.stderr)
    return EXIT_FAILURE


def _main(argv: Sequence[str] | None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format='%(levelname)s %(name)s: %(message)s')
    try:
        if args.command == 'run':
            from ttb_sim.commands.run import run
            return run(args.scenario, out=args.out, storage=args.storage,
                       overrides=args.overrides, speed_kmh=args.speed_kmh,
                       duration=args.duration, force=args.force)
        if args.command == 'validate':
            from ttb_sim.commands.validate import validate
            return validate(args.cases, list_only=args.list)
        if args.command == 'analyze':
            from ttb_sim.commands.analyze import analyze
            return analyze(args.bag, out=args.out, modes_window=args.modes_window)
        if args.command == 'recover':
            from ttb_sim.commands.recover import recover
            return recover(args.bag, out=args.out)
        if args.command == 'compare':
            from ttb_sim.commands.compare import compare
            return compare(args.bags, labels=args.labels, out=args.out)
        if args.command == 'sweep':
            from ttb_sim.commands.sweep import sweep
            return sweep(args.scenario, speeds_kmh=args.speeds_kmh, seeds=args.seeds,
                         overrides=args.overrides, out=args.out, workers=args.workers,
                         scheduler=args.scheduler, duration=args.duration,
                         storage=args.storage, force=args.force)
        if args.command == 'dataset':
            from ttb_sim.commands.dataset import dataset
            return dataset(args.spec, out=args.out, n=args.n, workers=args.workers,
                           scheduler=args.scheduler, force=args.force)
        if args.command == 'identify':
            from ttb_sim.commands.identify import identify_command
            return identify_command(args.bag, args.params, out=args.out, scenario=args.scenario,
                                    overrides=args.overrides, sensors=args.sensors,
                                    design=args.design, steps=args.steps, walkers=args.walkers,
                                    seed=args.seed, discrepancy=args.discrepancy,
                                    fmin=args.fmin, fmax=args.fmax, points=args.points,
                                    segment=args.segment, response=args.response,
                                    workers=args.workers, scheduler=args.scheduler,
                                    refine=args.refine)
        if args.command == 'bench':
            from ttb_sim.commands.bench import bench_command
            return bench_command(args.scenarios, variants=args.variants,
                                 duration=args.duration, json_path=args.json,
                                 repeat=args.repeat, isolate=not args.in_process,
                                 overrides=args.overrides, threads=args.threads)
        if args.command == 'frf':
            from ttb_sim.commands.frf import frf_command
            return frf_command(args.scenario, args.freqs, pml=args.pml, refine=args.refine,
                               solver=args.solver, overrides=args.overrides,
                               json_path=args.json, plot_path=args.plot, at=args.at,
                               reduced=args.reduced)
        if args.command == 'modes':
            from ttb_sim.commands.modes import modes_command
            return modes_command(args.scenario, around=args.around, count=args.count,
                                 overrides=args.overrides, json_path=args.json)
        from ttb_sim.commands.scenarios import scenarios
        return scenarios(keys=args.keys)
    except (ScenarioError, ModelError) as exc:
        print(f'ttb-sim: error: {one_line(exc)}', file=sys.stderr)
        return EXIT_USAGE
    except TtbSimError as exc:
        print(f'ttb-sim: failed: {one_line(exc)}', file=sys.stderr)
        return EXIT_FAILURE
    except OSError as exc:  # a path the verb did not check itself (a name too long, say)
        return _os_error(exc)
    except BrokenPipeError:  # stdout closed early (`ttb-sim scenarios | head`): not an error
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except KeyboardInterrupt:  # before a verb installed its own handler
        print('ttb-sim: stopped by SIGINT', file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == '__main__':  # pragma: no cover
    entry()
