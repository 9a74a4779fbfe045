#!/bin/bash
# Side by side, interleaved: OLD = a clone at f7d08a1 with its own venv (.venv), NEW = a clone of
# the new code run with the system python (PYTHONPATH). Results go to the current folder; the
# medians are taken from the five lines of each file. Usage: OLD=/path NEW=/path bash side_by_side_bench.sh
OLD=${OLD:?clone of the old code with .venv}; NEW=${NEW:?clone of the new code}
HERE=$(cd "$(dirname "$0")" && pwd)
for r in 1 2 3 4 5; do
  uptime >> load.txt
  (cd $OLD && .venv/bin/patrolsb3 bench train --repeats 1) >> old_train.jsonl 2>>err.txt
  (cd $NEW && PYTHONPATH=$NEW patrolsb3 bench train --repeats 1) >> new_train.jsonl 2>>err.txt
  (cd $OLD && .venv/bin/python $HERE/pettingzoo_speed.py old) >> old_pz.txt 2>>err.txt
  (cd $NEW && PYTHONPATH=$NEW python $HERE/pettingzoo_speed.py new) >> new_pz.txt 2>>err.txt
done
uptime >> load.txt
echo done > done.txt
