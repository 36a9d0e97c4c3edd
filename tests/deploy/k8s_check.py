#!/usr/bin/python3
"""Static checks of deploy/k8s: yamllint, `kubectl kustomize` renders the base
and every overlay, and the rendered objects agree with the server:

- every container has CPU and memory limits and requests, and its memory
  limit holds the server (300 MB) and STYLUS_MAX_MEMORY_MB;
- pods run as non-root, with no privilege escalation and a read-only root;
- the gRPC probes (startup, readiness, liveness) use the port the server
  listens on (STYLUS_LISTEN in the flags ConfigMap) and the container's
  `grpc` port;
- terminationGracePeriodSeconds covers the preStop sleep plus the server's
  drain (STYLUS_SHUTDOWN_GRACE_S);
- the Services target the `grpc` port.

It then breaks a copy of the rendered base three ways and checks each is
caught. Usage: k8s_check.py SOURCE_DIR
"""
import copy
import os
import subprocess
import sys

import yaml

src = sys.argv[1]
failures = []


def check(name, ok, detail=""):
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + str(detail)))
    if not ok:
        failures.append(name)


def render(path):
    out = subprocess.run(["kubectl", "kustomize", path], capture_output=True, text=True)
    check("kubectl kustomize " + path, out.returncode == 0, out.stderr[-500:])
    return [d for d in yaml.safe_load_all(out.stdout) if d]


def problems(objects):
    """What is wrong with a rendered set of objects (empty: nothing)."""
    found = []
    maps = {o["metadata"]["name"]: o.get("data", {}) for o in objects if o["kind"] == "ConfigMap"}
    for d in (o for o in objects if o["kind"] == "Deployment"):
        pod = d["spec"]["template"]["spec"]
        pod_sc = pod.get("securityContext", {})
        for c in pod["containers"]:
            name = "%s/%s" % (d["metadata"]["name"], c["name"])
            res = c.get("resources", {})
            for kind in ("limits", "requests"):
                for r in ("cpu", "memory"):
                    if r not in res.get(kind, {}):
                        found.append("%s has no %s %s" % (name, r, kind))
            sc = c.get("securityContext", {})
            if not (sc.get("runAsNonRoot", pod_sc.get("runAsNonRoot")) is True):
                found.append(name + " may run as root")
            if sc.get("runAsUser", pod_sc.get("runAsUser", 0)) == 0:
                found.append(name + " runs as uid 0")
            if sc.get("allowPrivilegeEscalation") is not False:
                found.append(name + " allows privilege escalation")
            if sc.get("readOnlyRootFilesystem") is not True:
                found.append(name + " has a writable root filesystem")
            env = {}
            for src_ref in c.get("envFrom", []):
                env.update(maps.get(src_ref.get("configMapRef", {}).get("name"), {}))
            for e in c.get("env", []):
                env[e["name"]] = e.get("value", "")
            listen = env.get("STYLUS_LISTEN", "0.0.0.0:50051")
            port = int(listen.rsplit(":", 1)[1])
            ports = {p.get("name"): p["containerPort"] for p in c.get("ports", [])}
            if ports.get("grpc") != port:
                found.append("%s: container port grpc %s, server listens on %s" %
                             (name, ports.get("grpc"), port))
            for probe in ("startupProbe", "readinessProbe", "livenessProbe"):
                p = c.get(probe, {}).get("grpc", {}).get("port")
                if p != port:
                    found.append("%s: %s gRPC port %s, server listens on %s" % (name, probe, p, port))
            # Memory: the server with its models (about 230 MB measured,
            # 300 allowed) plus what its calls may hold (--max-memory-mb,
            # 2048 by default) must fit the limit.
            limit = res.get("limits", {}).get("memory", "0")
            units = {"Ki": 1 / 1024, "Mi": 1, "Gi": 1024}
            suffix = [f for u, f in units.items() if limit.endswith(u)]
            limit_mb = float(limit[:-2]) * suffix[0] if suffix else float(limit or 0) / (1 << 20)
            pool_mb = float(env.get("STYLUS_MAX_MEMORY_MB", "2048"))
            if "command" not in c and (pool_mb <= 0 or pool_mb + 300 > limit_mb):
                found.append("%s: memory limit %s MB < 300 MB + STYLUS_MAX_MEMORY_MB %s" %
                             (name, limit_mb, pool_mb))
            grace = float(env.get("STYLUS_SHUTDOWN_GRACE_S", "10"))
            pre = c.get("lifecycle", {}).get("preStop", {}).get("exec", {}).get("command", [])
            pre_s = float(pre[1]) if len(pre) == 2 and pre[0] == "sleep" else 0
            total = pod.get("terminationGracePeriodSeconds", 30)
            if total < pre_s + grace + 1:
                found.append("%s: terminationGracePeriodSeconds %s < preStop %s + drain %s + 1" %
                             (name, total, pre_s, grace))
    for s in (o for o in objects if o["kind"] == "Service"):
        for p in s["spec"]["ports"]:
            if p["name"] == "grpc" and p.get("targetPort") != "grpc":
                found.append("service %s targets %s, not the grpc port" %
                             (s["metadata"]["name"], p.get("targetPort")))
    if not any(o["kind"] == "Deployment" for o in objects):
        found.append("no Deployment")
    return found


lint = subprocess.run(["yamllint", "-c", src + "/deploy/k8s/.yamllint", src + "/deploy/k8s"],
                      capture_output=True, text=True)
check("yamllint deploy/k8s", lint.returncode == 0, lint.stdout[-800:])

base = render(src + "/deploy/k8s/base")
for path in ("base", "overlays/example"):
    objects = base if path == "base" else render(src + "/deploy/k8s/" + path)
    found = problems(objects)
    check("rendered %s passes" % path, not found, "; ".join(found))
    kinds = sorted({o["kind"] for o in objects})
    print("     %s: %s" % (path, ", ".join(kinds)))

example = render(src + "/deploy/k8s/overlays/example")
for want in ("HorizontalPodAutoscaler", "PodDisruptionBudget", "ServiceMonitor", "ConfigMap"):
    check("the example has a " + want, any(o["kind"] == want for o in example))
check("the example mounts the TLS and token secrets",
      {"stylus-tls", "stylus-tokens"} <= {v.get("secret", {}).get("secretName") for o in example
                                          if o["kind"] == "Deployment"
                                          for v in o["spec"]["template"]["spec"].get("volumes", [])})


# The Indexed Job of an offline library: one shard per completion index.
job = yaml.safe_load(open(src + "/deploy/k8s/jobs/transfer-library.yaml"))
spec = job["spec"]
command = spec["template"]["spec"]["containers"][0]["command"]
shards = int(command[command.index("--shard-count") + 1]) if "--shard-count" in command else 0
check("the library job is Indexed", spec.get("completionMode") == "Indexed")
check("the job's completions equal its --shard-count", spec.get("completions") == shards,
      "%s completions, %s shards" % (spec.get("completions"), shards))
# It names its package by version (a library restyles with one network):
# that version must be one the image ships (deploy/Containerfile copies
# models/ to /opt/stylus/models).
package = command[command.index("--model") + 1] if "--model" in command else ""
prefix = "/opt/stylus/models/"
check("the library job's package is one the image ships",
      package.startswith(prefix) and
      os.path.isfile(os.path.join(src, "models", package[len(prefix):], "config.txt")),
      package or "no --model")
found = problems([{"kind": "Deployment", "metadata": job["metadata"],
                   "spec": {"template": spec["template"]}}])
# A job has no gRPC port or probes: only the container rules apply.
found = [f for f in found if "port" not in f and "listens" not in f]
check("the job's container has limits and runs as non-root", not found, "; ".join(found))

# The checks catch what they are for.
def broken(change):
    objects = copy.deepcopy(base)
    dep = next(o for o in objects if o["kind"] == "Deployment")
    change(dep["spec"]["template"]["spec"])
    return problems(objects)


def wrong_probe(pod):
    pod["containers"][0]["readinessProbe"]["grpc"]["port"] = 50052


def short_grace(pod):
    pod["terminationGracePeriodSeconds"] = 5


def no_limits(pod):
    del pod["containers"][0]["resources"]["limits"]


def small_memory(pod):
    pod["containers"][0]["resources"]["limits"]["memory"] = "512Mi"


for name, change in (("a wrong probe port", wrong_probe), ("a grace shorter than the drain",
                     short_grace), ("a container without limits", no_limits),
                     ("a memory limit below the server's bound", small_memory)):
    check("catches " + name, bool(broken(change)))

print("%d failed" % len(failures))
sys.exit(1 if failures else 0)
