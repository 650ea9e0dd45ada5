"""The real link between the brain side and the robot side (docs/guide/links.md).

In simulated time the link is the tick-grid delay channel of ``delay_channel.py``. With a real link the
two sides are separate processes joined by a registered transport (``zenoh``, ``udp``; a plugin may
add more), exchanging authenticated packets of the versioned wire format (``wire.py``):

=================  ===========================================================================
module             what it holds
=================  ===========================================================================
``wire.py``        the packet layout, encoding, and every reason a packet is refused
``auth.py``        the shared key (from a file or the environment, never from the config), HMAC
``schema.py``      the ``link`` and ``realtime`` configuration
``transport.py``   the transport contract (bytes on the ``r2c``/``c2r`` paths), endpoints, inbox
``zenoh_link.py``  zenoh peers on explicit TCP endpoints (the default real transport)
``udp.py``         plain UDP datagrams
``channel.py``     one side's end of the link: messages in and out, counters, measured delays
``clock.py``       the monotonic clock, tick pacing and the clock-offset estimate
``pairing.py``     the handshake: config fingerprints, run id, clock sync, the start time
``shedding.py``    the brain side's watchdog (the original's real-time restriction)
``relay.py``       the delay-injecting relay process on the path
``trace.py``       measured delays of a run: export for ``delay=trace``, comparison with the model
=================  ===========================================================================
"""
