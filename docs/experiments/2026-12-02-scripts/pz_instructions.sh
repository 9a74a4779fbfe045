#!/bin/bash
# Instructions per simulator step of the PettingZoo env (callgrind; independent of the machine's load):
# for each LABEL=PYTHON:ROOT, the instruction counts of 200 and 1,200 simulator steps of pz_speed.py's
# loop, their difference / 1,000. Usage: bash pz_instructions.sh old=/venv/bin/python:/old new=python:/new
HERE=$(cd "$(dirname "$0")" && pwd)
for spec in "$@"; do
  label=${spec%%=*}; rest=${spec#*=}; py=${rest%%:*}; root=${rest#*:}
  py=$($py -c "import sys; print(sys.executable)")
  for n in 200 1200; do
    PYTHONHASHSEED=0 valgrind --tool=callgrind --callgrind-out-file=/tmp/cg.$label.$n $py "$HERE/pz_speed.py" "$root" "$label" $n 2>&1 \
      | sed -n 's/.*Collected : \([0-9]*\).*/\1/p' > /tmp/cg.$label.$n.count
  done
  a=$(cat /tmp/cg.$label.200.count); b=$(cat /tmp/cg.$label.1200.count)
  echo "$label $(( (b - a) / 1000 )) instructions per simulator step"
done
