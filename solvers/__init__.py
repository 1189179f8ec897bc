"""Pure numerical kernels of rrc-pin: numpy and QP backends only (no Pinocchio, no files).

Imported as ``rrc_pin.solvers`` (the folder sits at the repository's top level, beside
``rrc_pin/``, and ``rrc_pin/solvers`` links to it): by concern, ``tick`` (one resolver tick),
``qp_backends``, ``collision``, ``maps``, ``closed_form``, and the shared ``checks``,
``spatial`` and ``errors``.
"""
