#!/usr/bin/env python3
"""An independent ROS 2 action client of Nav2's docking interface over Zenoh.

Written from rmw_zenoh's design document and sources (key expressions, the 33-byte
attachment, queries for services) and from Nav2's `nav2_msgs/action/DockRobot.action`
and `UndockRobot.action` (field order and types), with the CDR (XCDR1, little-endian)
encoded here by hand. It shares no code with the crate: the type hashes below are the
`hash_string`s rosidl wrote for a public Nav2 build, not the crate's.

Usage: nav2_peer.py LOCATOR DOMAIN DOCK_ID
  LOCATOR  the node's Zenoh endpoint (tcp/127.0.0.1:PORT); the only one connected to
  DOMAIN   the ROS domain
  DOCK_ID  the dock to dock at

It undocks (UndockRobot), waits, docks by dock_id (DockRobot), checking that feedback
states come in a docking's order, sends an unknown dock_id and checks DOCK_NOT_IN_DB
with a message naming `dock_id`, then starts an undocking and cancels it
(`action_msgs/srv/CancelGoal`, whose hash it computes itself by REP-2011's rules, as
`rosidl_generator_type_description` does: no published value was found for it). Exit
code 0 when every check holds.
"""

import hashlib
import json
import os
import struct
import sys
import threading
import time

import zenoh

HASH = {
    "DockRobot_SendGoal": "RIHS01_9e60155a1fb741109942c5c7dc21ae0e0db771eaf55d0cfc768bae57a95f3454",
    "DockRobot_GetResult": "RIHS01_3e83e8a6eefb3ebe244cd0384418f43d22ffb1f3263fd7b978af8164591c50b3",
    "DockRobot_FeedbackMessage": "RIHS01_16db0109537f6d74013ed7e6fa51f21c6dcc0a0355cef3be4db4401e971bbe81",
    "UndockRobot_SendGoal": "RIHS01_9c412dec37b7dad67b754dd860cdb03787c0924f01d4cd2b5c16506726b17dc3",
    "UndockRobot_GetResult": "RIHS01_116641408dd0a5bbb7f0cb61d4519061884c7fcc70ca78b0f89779459cf04263",
}



def fld(name, type_id, nested="", capacity=0):
    t = {"type_id": type_id, "capacity": capacity, "string_capacity": 0, "nested_type_name": nested}
    return {"name": name, "type": t}


def type_hash(top, library):
    """REP-2011 (RIHS01): SHA-256 of the JSON of the type's description and every type it
    reaches, sorted by name, default values left out."""
    refs, queue = {}, [f["type"]["nested_type_name"] for f in top["fields"]]
    while queue:
        n = queue.pop()
        if n and n not in refs:
            refs[n] = library[n]
            queue += [f["type"]["nested_type_name"] for f in library[n]["fields"]]
    doc = {"type_description": top, "referenced_type_descriptions": [refs[k] for k in sorted(refs)]}
    text = json.dumps(doc, separators=(", ", ": "))
    return "RIHS01_" + hashlib.sha256(text.encode()).hexdigest()


def cancel_goal_hash():
    """`action_msgs/srv/CancelGoal`: request `GoalInfo goal_info`; response `int8
    return_code`, `GoalInfo[] goals_canceling`; and the service's event message."""
    NESTED, INT8, UINT8, INT32, UINT32, INT64, UINT8_ARRAY = 1, 2, 3, 6, 7, 8, 51
    NESTED_BOUNDED, NESTED_SEQUENCE = 97, 145
    srv = "action_msgs/srv/CancelGoal"
    lib = {
        "builtin_interfaces/msg/Time": [fld("sec", INT32), fld("nanosec", UINT32)],
        "unique_identifier_msgs/msg/UUID": [fld("uuid", UINT8_ARRAY, capacity=16)],
        "action_msgs/msg/GoalInfo": [
            fld("goal_id", NESTED, "unique_identifier_msgs/msg/UUID"),
            fld("stamp", NESTED, "builtin_interfaces/msg/Time"),
        ],
        "service_msgs/msg/ServiceEventInfo": [
            fld("event_type", UINT8),
            fld("stamp", NESTED, "builtin_interfaces/msg/Time"),
            fld("client_gid", UINT8_ARRAY, capacity=16),
            fld("sequence_number", INT64),
        ],
        srv + "_Request": [fld("goal_info", NESTED, "action_msgs/msg/GoalInfo")],
        srv + "_Response": [
            fld("return_code", INT8),
            fld("goals_canceling", NESTED_SEQUENCE, "action_msgs/msg/GoalInfo"),
        ],
        srv + "_Event": [
            fld("info", NESTED, "service_msgs/msg/ServiceEventInfo"),
            fld("request", NESTED_BOUNDED, srv + "_Request", 1),
            fld("response", NESTED_BOUNDED, srv + "_Response", 1),
        ],
    }
    library = {k: {"type_name": k, "fields": v} for k, v in lib.items()}
    top = {
        "type_name": srv,
        "fields": [
            fld("request_message", NESTED, srv + "_Request"),
            fld("response_message", NESTED, srv + "_Response"),
            fld("event_message", NESTED, srv + "_Event"),
        ],
    }
    return type_hash(top, library)


HASH["CancelGoal"] = cancel_goal_hash()

# DockRobot.action constants.
NAV_TO_STAGING_POSE, INITIAL_PERCEPTION, CONTROLLING, WAIT_FOR_CHARGE, RETRY = 1, 2, 3, 4, 5
DOCK_NOT_IN_DB = 901
STATUS_SUCCEEDED, STATUS_CANCELED, STATUS_ABORTED = 4, 5, 6


class Writer:
    """XCDR1 little-endian: a 4-byte encapsulation header, then each primitive aligned
    to its size, counted from the end of the header."""

    def __init__(self):
        self.b = bytearray(b"\x00\x01\x00\x00")

    def align(self, n):
        while (len(self.b) - 4) % n:
            self.b.append(0)

    def put(self, fmt, v):
        size = struct.calcsize(fmt)
        self.align(size)
        self.b += struct.pack("<" + fmt, v)

    def string(self, s):
        data = s.encode() + b"\x00"
        self.put("I", len(data))
        self.b += data

    def raw(self, data):
        self.b += data


class Reader:
    def __init__(self, b):
        if len(b) < 4 or b[1] != 1:
            raise ValueError("not little-endian CDR")
        self.b, self.i = b, 4

    def get(self, fmt):
        size = struct.calcsize(fmt)
        while (self.i - 4) % size:
            self.i += 1
        (v,) = struct.unpack_from("<" + fmt, self.b, self.i)
        self.i += size
        return v

    def string(self):
        n = self.get("I")
        s = self.b[self.i : self.i + n - 1].decode()
        self.i += n
        return s

    def raw(self, n):
        v = self.b[self.i : self.i + n]
        self.i += n
        return v


class Client:
    def __init__(self, session, domain):
        self.s, self.domain, self.seq = session, domain, 0
        self.gid = os.urandom(16)

    def key(self, name, type_name, package="nav2_msgs", kind="action"):
        return f"{self.domain}/{name}/{package}::{kind}::dds_::{type_name}_/{HASH[type_name]}"

    def attachment(self):
        self.seq += 1
        return struct.pack("<qqB", self.seq, time.time_ns(), 16) + self.gid

    def call(self, key, payload, timeout):
        replies = self.s.get(
            key,
            payload=bytes(payload),
            attachment=self.attachment(),
            target=zenoh.QueryTarget.ALL_COMPLETE,
            timeout=timeout,
        )
        for reply in replies:
            if reply.ok is not None:
                return reply.ok.payload.to_bytes()
        raise RuntimeError(f"no answer from {key}")

    def send(self, action, type_prefix, goal_fields, deadline_s=20.0):
        """SendGoal: a fresh UUID and the goal; retried while the link comes up."""
        goal_id = os.urandom(16)
        w = Writer()
        w.raw(goal_id)
        goal_fields(w)
        key = self.key(f"{action}/_action/send_goal", f"{type_prefix}_SendGoal")
        end = time.time() + deadline_s
        while True:
            try:
                r = Reader(self.call(key, w.b, 2.0))
                if r.get("B") != 1:
                    raise RuntimeError("goal rejected")
                return goal_id
            except RuntimeError:
                if time.time() > end:
                    raise
                time.sleep(0.2)

    def result(self, action, type_prefix, goal_id, dock, timeout):
        w = Writer()
        w.raw(goal_id)
        key = self.key(f"{action}/_action/get_result", f"{type_prefix}_GetResult")
        r = Reader(self.call(key, w.b, timeout))
        out = {"status": r.get("b"), "success": r.get("B") != 0, "error_code": r.get("H")}
        if dock:
            out["num_retries"] = r.get("H")
        out["error_msg"] = r.string()
        return out


def dock_goal(dock_id, use_dock_id=True):
    def fields(w):
        w.put("B", 1 if use_dock_id else 0)
        w.string(dock_id)
        w.put("i", 0)  # dock_pose.header.stamp
        w.put("I", 0)
        w.string("")  # dock_pose.header.frame_id
        for v in (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0):  # position, orientation
            w.put("d", v)
        w.string("")  # dock_type
        w.put("f", 1000.0)  # max_staging_time
        w.put("B", 1)  # navigate_to_staging_pose

    return fields


def undock_goal(max_undocking_time):
    def fields(w):
        w.string("")  # dock_type
        w.put("f", max_undocking_time)

    return fields


def main():
    locator, domain, dock_id = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("connect/endpoints", json.dumps([locator]))
    conf.insert_json5("listen/endpoints", "[]")
    conf.insert_json5("scouting/multicast/enabled", "false")
    checks = []
    with zenoh.open(conf) as session:
        c = Client(session, domain)
        t0 = time.time()
        gid = c.send("undock_robot", "UndockRobot", undock_goal(90.0))
        r = c.result("undock_robot", "UndockRobot", gid, False, 120.0)
        checks.append(("undock succeeded", r["status"] == STATUS_SUCCEEDED and r["success"], r))
        time.sleep(1.0)  # the harness places the robot at the run's start

        states = []
        lock = threading.Lock()

        def on_feedback(sample):
            r = Reader(sample.payload.to_bytes())
            r.raw(16)
            state = r.get("H")
            with lock:
                states.append(state)

        sub = session.declare_subscriber(
            c.key("dock_robot/_action/feedback", "DockRobot_FeedbackMessage"), on_feedback
        )
        gid = c.send("dock_robot", "DockRobot", dock_goal(dock_id))
        r = c.result("dock_robot", "DockRobot", gid, True, 200.0)
        sub.undeclare()
        checks.append(("docked", r["status"] == STATUS_SUCCEEDED and r["success"], r))
        with lock:
            trail = [s for i, s in enumerate(states) if i == 0 or states[i - 1] != s]
        known = all(0 <= s <= RETRY for s in trail)
        first = lambda s: trail.index(s) if s in trail else None
        ordered = (
            first(CONTROLLING) is not None
            and (first(INITIAL_PERCEPTION) is None or first(INITIAL_PERCEPTION) < first(CONTROLLING))
            and next((s for s in trail if s != 0), None) in (INITIAL_PERCEPTION, NAV_TO_STAGING_POSE)
        )
        checks.append(("feedback states in a docking's order", known and ordered, trail))

        gid = c.send("dock_robot", "DockRobot", dock_goal("no_such_dock"))
        r = c.result("dock_robot", "DockRobot", gid, True, 10.0)
        checks.append(
            (
                "unknown dock_id: DOCK_NOT_IN_DB naming dock_id",
                r["status"] == STATUS_ABORTED and r["error_code"] == DOCK_NOT_IN_DB and "dock_id" in r["error_msg"],
                r,
            )
        )
        # A cancel stops an undocking: CancelGoal accepts (return code 0), the result is
        # CANCELED.
        gid = c.send("undock_robot", "UndockRobot", undock_goal(90.0))
        time.sleep(1.0)
        w = Writer()
        w.raw(gid)
        w.put("i", 0)
        w.put("I", 0)
        key = c.key("undock_robot/_action/cancel_goal", "CancelGoal", "action_msgs", "srv")
        code = Reader(c.call(key, w.b, 5.0)).get("b")
        r = c.result("undock_robot", "UndockRobot", gid, False, 20.0)
        checks.append(
            ("a cancel ends the undocking CANCELED", code == 0 and r["status"] == STATUS_CANCELED, (code, r))
        )
        print(f"peer: {time.time() - t0:.1f} s; CancelGoal hash computed here: {HASH['CancelGoal']}")
    ok = True
    for name, passed, detail in checks:
        print(f"{'ok  ' if passed else 'FAIL'} {name}: {detail}")
        ok &= bool(passed)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
