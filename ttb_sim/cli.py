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
The ``ttb-sim`` command: run, validate and list scenarios without ROS.

Exit codes: 0 success; 1 numerical failure (divergence) or failed validation;
2 bad scenario or argument; 130 / 143 interrupted by SIGINT / SIGTERM.
"""

from __future__ import annotations

import argparse
import logging
from pathlib import Path
import signal
import sys
from typing import Sequence

from ttb_sim import __version__
from ttb_sim.errors import ScenarioError, TtbSimError

log = logging.getLogger('ttb_sim')

EXIT_OK, EXIT_FAILURE, EXIT_USAGE = 0, 1, 2


class _StopFlag:
    """Signal handler that records SIGINT / SIGTERM for the run loop to poll."""

    def __init__(self) -> None:
        self.signal: int | None = None

    def __call__(self, signum: int, frame: object) -> None:
        self.signal = signum

    def __bool__(self) -> bool:
        return self.signal is not None


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog='ttb-sim', description='Train-track-bridge dynamics: '
                                'run scenarios offline to rosbag2, validate the physics.')
    p.add_argument('--version', action='version', version=f'%(prog)s {__version__}')
    p.add_argument('-v', '--verbose', action='store_true', help='log progress details')
    sub = p.add_subparsers(dest='command', required=True, metavar='COMMAND')

    run = sub.add_parser('run', help='simulate a scenario and record a rosbag2')
    run.add_argument('scenario', help='YAML path or built-in name (see `ttb-sim scenarios`)')
    run.add_argument('--out', type=Path, help='bag directory to create (default: a new '
                     'folder under ./runs/)')
    run.add_argument('--speed-kmh', type=float, help='override train.speed_kmh')
    run.add_argument('--duration', type=float, help='override solver.duration (s)')
    run.add_argument('--storage', default='mcap', choices=('mcap', 'sqlite3'),
                     help='rosbag2 storage (default mcap)')
    run.add_argument('--set', dest='overrides', action='append', default=[],
                     metavar='KEY=VALUE', help='override a scenario key (YAML scalar); '
                     'repeatable')

    val = sub.add_parser('validate', help='run the validation suite and print a table')
    val.add_argument('cases', nargs='*', metavar='CASE', help='case ids (default: all)')
    val.add_argument('--list', action='store_true', help='list the cases and exit')

    be = sub.add_parser('bench', help='time the solver variants side by side and compare '
                        'their results with the reference variant')
    be.add_argument('scenarios', nargs='*', metavar='SCENARIO',
                    help='YAML paths or built-in names (default: ten_span_train, and '
                    'paper_ttbi for 0.05 s)')
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

    sc = sub.add_parser('scenarios', help='list the built-in scenarios')
    sc.add_argument('--keys', action='store_true',
                    help='list every scenario key with unit, default and range')
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    parser = _parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format='%(levelname)s %(name)s: %(message)s')
    try:
        if args.command == 'run':
            return _cmd_run(args)
        if args.command == 'validate':
            return _cmd_validate(args)
        if args.command == 'bench':
            return _cmd_bench(args)
        return _cmd_scenarios(args)
    except ScenarioError as exc:
        print(f'ttb-sim: error: {exc}', file=sys.stderr)
        return EXIT_USAGE
    except TtbSimError as exc:
        print(f'ttb-sim: failed: {exc}', file=sys.stderr)
        return EXIT_FAILURE


def _cmd_run(args: argparse.Namespace) -> int:
    from ttb_sim.runner import default_output, run_to_bag
    from ttb_sim.scenario import load_scenario
    from ttb_sim.sim.simulation import Simulation

    values = []
    if args.speed_kmh is not None:
        values.append(('train.speed_kmh', args.speed_kmh))
    if args.duration is not None:
        values.append(('solver.duration', args.duration))
    scenario = load_scenario(args.scenario, args.overrides, values)
    simulation = Simulation(scenario)
    out = args.out if args.out is not None else default_output(scenario.name)
    bar = None
    if sys.stderr.isatty():
        from tqdm import tqdm
        bar = tqdm(total=simulation.n_frames, unit='frame', desc=scenario.name,
                   file=sys.stderr, leave=False)
    stop = _StopFlag()
    previous = {sig: signal.signal(sig, stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        result = run_to_bag(scenario, out, args.storage,
                            progress=bar.update if bar is not None else None,
                            simulation=simulation, should_stop=stop.__bool__)
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if bar is not None:
            bar.close()
    s = result.summary
    if result.status == 'interrupted':
        name = signal.Signals(stop.signal).name if stop.signal else 'signal'
        print(f'ttb-sim: stopped by {name}; bag closed at {out} with {s["frames"]} frames',
              file=sys.stderr)
        return 128 + (stop.signal or signal.SIGINT)
    if result.status == 'diverged':
        print(f'ttb-sim: failed: {s["message"]}; bag closed at {out} with {s["frames"]} '
              'frames', file=sys.stderr)
        return EXIT_FAILURE
    print(f'{out}: {s["frames"]} frames, {s["simulated_time"]:.3f} s simulated in '
          f'{s["wall_time"]:.2f} s (real-time factor {s["real_time_factor"]:.3g})')
    return EXIT_OK


def _cmd_validate(args: argparse.Namespace) -> int:
    from ttb_sim.validation.cases import CASES, format_table, run_cases

    if args.list:
        for case_id, case in CASES.items():
            print(f'{case_id:5s} {case.title}')
        return EXIT_OK
    unknown = [c for c in args.cases if c not in CASES]
    if unknown:
        raise ScenarioError(f'unknown validation case(s) {", ".join(unknown)}; allowed: '
                            f'{", ".join(CASES)}')
    rows = run_cases(args.cases or list(CASES))
    print(format_table(rows))
    failed = sum(not r.passed for r in rows)
    print(f'{len(rows) - failed} passed, {failed} failed')
    return EXIT_OK if failed == 0 else EXIT_FAILURE


def _cmd_bench(args: argparse.Namespace) -> int:
    from ttb_sim.commands.bench import bench, format_table, write_json

    variants = [v.strip() for v in (args.variants or '').split(',') if v.strip()]
    report = bench(args.scenarios, variants, args.duration, overrides=args.overrides,
                   repeat=args.repeat, isolate=not args.in_process,
                   progress=lambda line: print(f'bench: {line}', file=sys.stderr))
    print(format_table(report))
    if args.json is not None:
        write_json(report, args.json)
    return EXIT_OK


def _cmd_scenarios(args: argparse.Namespace) -> int:
    from ttb_sim.scenario import builtin_scenarios, iter_keys, read_yaml

    if args.keys:
        for key, _typ, default, spec in iter_keys():
            dyn = ' (dynamic)' if spec.dynamic else ''
            print(f'{key:34s} {spec.unit:9s} default {default!r:14} {spec.allowed()}{dyn}\n'
                  f'{"":34s} {spec.description}')
        return EXIT_OK
    for name, path in builtin_scenarios().items():
        try:
            description = (read_yaml(path.read_text(encoding='utf-8')) or {}).get(
                'description', '')
        except Exception:  # noqa: B902 - listing must not fail on one bad file
            description = '(unreadable)'
        print(f'{name:22s} {description}')
    return EXIT_OK


if __name__ == '__main__':  # pragma: no cover
    sys.exit(main())
