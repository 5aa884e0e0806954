#!/usr/bin/env bash
# The docs page's example (docs/routing_geo.md): a time-optimal route from off Start Point to the Dover Strait
# at 12 kn through the analytic Channel tide, round Beachy Head and Dungeness, written as GPX, GeoJSON and RTZ.
#
#     bash examples/geo/run_channel_route.sh [OUT_DIR]        (default runs/channel-route)
set -euo pipefail
out=${1:-runs/channel-route}
data=$(mktemp -d)
trap 'rm -rf "$data"' EXIT
python examples/geo/make_channel_tide.py "$data/channel_tide.nc"
shipgnc route --geo --start 50.10,-3.60 --target 51.00,1.50 --speed 12 --units nautical \
    --field "$data/channel_tide.nc" --depart 2026-06-01T06:00Z --out "$out"
python examples/geo/departure_scan.py "$data/channel_tide.nc"
