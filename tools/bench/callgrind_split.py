#!/usr/bin/env python3
"""Splits the instructions of a callgrind profile of `accel-peers` between the parts of our
wide-BVH traversal (node box test, traversal control, stack, prefetch, ray set-up, leaf loop,
triangle test, triangle-test set-up), by the chain of inlined functions that `addr2line -i`
gives for each instruction address.

    valgrind --tool=callgrind --dump-instr=yes --toggle-collect='accel_peers::trace*' \
        --callgrind-out-file=OUT accel-peers MESH --rays DIR_WITH_ONE_SET --accel bvh8 \
        --peers none --runs 1 --check 0 --threads 1
    tools/bench/callgrind_split.py OUT ACCEL_PEERS_BINARY RAYS [CATEGORY]

Prints instructions per ray (the profile's exclusive costs in the binary divided by RAYS) per
category; with CATEGORY, also that category's instructions per source line.
"""
import collections
import re
import subprocess
import sys

# First match wins: an instruction of the triangle test inlined into the leaf loop inlined into
# the traversal counts as the triangle test.
RULES = [
    ("leaf: triangle test", ["intersect8_avx2", "intersect4", "watertight", "intersect_triangle"]),
    ("leaf: triangle set-up", ["RayPrecomp"]),
    ("leaf: offer hit", ["Closest>::offer"]),
    ("leaf: loop", ["test_leaf"]),
    ("node: prefetch", ["::prefetch"]),
    ("node: box test", ["hit8_avx2", "hit4", "as rt_accel::wide::bvh::WideNode>::hit"]),
    ("node: stack", ["Stack<"]),
    ("ray set-up", ["PreparedRay", "Slab>::new", "octant"]),
    ("node: traversal control", ["traverse"]),
]


def positions(token, previous):
    if token == "*":
        return previous
    if token[0] in "+-":
        return previous + int(token, 0)
    return int(token, 0)


def exclusive_costs(path, binary_name):
    """Instruction address -> exclusive Ir, for the addresses in the object `binary_name`."""
    costs = collections.Counter()
    names, obj, addr, after_call = {}, None, 0, False
    for line in open(path):
        line = line.rstrip("\n")
        if not line:
            continue
        m = re.match(r"(c?ob)=\((\d+)\)(?: (.*))?", line)
        if m:
            if m.group(3):
                names[m.group(2)] = m.group(3)
            if m.group(1) == "ob":
                obj = names.get(m.group(2), "")
            continue
        if line.startswith("calls="):
            after_call = True
            continue
        if line[0] in "0123456789+-*":
            parts = line.split()
            addr = positions(parts[0], addr)
            if after_call:  # the inclusive cost of a call, not this address's own
                after_call = False
            elif obj.endswith(binary_name) and len(parts) >= 3:
                costs[addr] += int(parts[2])
    return costs


def main():
    out, binary, rays = sys.argv[1], sys.argv[2], int(sys.argv[3])
    want = sys.argv[4] if len(sys.argv) > 4 else None
    costs = exclusive_costs(out, binary.split("/")[-1])
    addrs = sorted(costs)
    text = subprocess.run(
        ["addr2line", "-f", "-i", "-C", "-a", "-e", binary] + [hex(a) for a in addrs],
        capture_output=True, text=True, check=True,
    ).stdout.split("\n")
    chains, cur, i = {}, None, 0
    while i < len(text):
        if text[i].startswith("0x"):
            cur = int(text[i], 16)
            chains[cur] = []
            i += 1
        elif text[i]:
            chains[cur].append((text[i], text[i + 1] if i + 1 < len(text) else ""))
            i += 2
        else:
            i += 1
    per_cat, per_line = collections.Counter(), collections.Counter()
    for a, c in costs.items():
        chain = chains.get(a, [])
        funcs = [f for f, _ in chain]
        cat = "other: " + (funcs[-1][:60] if funcs else "?")
        for name, keys in RULES:
            if any(k in f for f in funcs for k in keys):
                cat = name
                break
        per_cat[cat] += c
        if cat == want and chain:
            per_line[chain[0][1].split("/")[-1]] += c
    for cat, c in per_cat.most_common():
        if c / rays >= 0.5:
            print(f"{c / rays:9.1f}  {cat}")
    print(f"{sum(per_cat.values()) / rays:9.1f}  total")
    for where, c in per_line.most_common(30):
        print(f"{c / rays:9.1f}  {where}")


if __name__ == "__main__":
    main()
