"""The rigid hybrid walker: the contract (:mod:`~walkerlab.models.hybrid.base`), the walker
generated from any description (:mod:`~walkerlab.models.hybrid.rigid`) and the paper's
compass gait with its printed equations (:mod:`~walkerlab.models.hybrid.printed_equations`)."""
