"""cerebx networks beside NEST and PyNN: ``cerebx export`` writes a network's exact synapse lists, neuron parameters
and input spike trains with a standalone NEST or PyNN script that builds it (:mod:`cerebx.export.writer`);
``cerebx crosscheck`` runs both simulators on the same input and compares them (:mod:`cerebx.export.crosscheck`).
What maps to what is one registry (:mod:`cerebx.export.mapping`): a new neuron, connector or plasticity kind adds
one entry there."""
