"""The compliant-contact walker: its run, periodic gait and step map, start-up adjustment,
drop test, rough ground, rigid limit, attribution of the gap and the comparison with the
rigid walker."""
