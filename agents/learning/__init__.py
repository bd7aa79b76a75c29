"""Learning: SB3 training (``train``), the RLlib multi-agent backend (``rllib_train``), the
batched SB3 VecEnv (``vecenv``) and loading any policy behind one interface (``policies``).
The modules need the ``rl`` (and for RLlib the ``multi``) extra; this package imports none."""
