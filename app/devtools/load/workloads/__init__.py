"""The load test's workloads, one module each: a soak of many clients, a storm of connections, a
flooding client, a hostile one, followers of a lead, a follower's rebuild, and contention between
sessions."""
