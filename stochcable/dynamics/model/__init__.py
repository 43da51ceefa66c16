"""One line's linear model about its static shape: the assembled system, its modes and
the objects the stages exchange (:mod:`~stochcable.dynamics.model.system`), its node-block
numerics and sea-independent arrays (:mod:`~stochcable.dynamics.model.blocks`), the
banded direct and modal solvers (:mod:`~stochcable.dynamics.model.solvers`,
:mod:`~stochcable.dynamics.model.modal_solvers`; the compiled banded Cholesky sweep in
:mod:`~stochcable.dynamics.model.band_kernels`) and the strumming screening applied at
build (:mod:`~stochcable.dynamics.model.strumming`)."""
