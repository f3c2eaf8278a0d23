r"""Plusieurs cibles dans le fouillis : porte de validation, association (NN, GNN, PDA, JPDA), gestion des
pistes et métriques (OSPA, GOSPA).

Étage au-dessus des filtres (il n'importe que ``core``) : ``gate.py`` (NIS, seuil et volume de la porte),
``assignment.py`` (plus proche voisin glouton et global), ``pda.py`` (poids et correction PDA),
``jpda.py`` (probabilités conjointes, énumération exacte par grappes), ``tracker.py`` (naissance par deux
points, confirmation M sur N, suppression) et ``metrics.py`` (OSPA, GOSPA et sa décomposition). Les
conventions suivent celles de Stone Soup 1.9.1, référence des tests (``tests/test_multitarget.py``).
"""

from .assignment import gnn_assign, nn_assign
from .gate import Gate, validation_gate
from .jpda import jpda_probabilities
from .metrics import GOSPA, gospa, ospa
from .pda import PDAUpdate, pda_update
from .tracker import MultiTargetResult, multi_target_tracker

__all__ = ["Gate", "validation_gate", "nn_assign", "gnn_assign", "PDAUpdate", "pda_update", "jpda_probabilities",
           "GOSPA", "gospa", "ospa", "MultiTargetResult", "multi_target_tracker"]
