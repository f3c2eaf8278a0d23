"""Les extensions Sphinx du livre, chargées par ``_config.yml`` (``sphinx: extra_extensions``) et par
lui seul : aucun autre module du paquet ne les importe.

- :mod:`.typography` : typographie française du texte courant (règles de :mod:`kalman_course.typography`) ;
- :mod:`.citations` : citations et bibliographies auteur–année en français ;
- :mod:`.listings` : directive ``{kc-source}``, code du paquet sans sa docstring ;
- :mod:`.quiz` : directive ``quiz``, questionnaires corrigés dans la page (et réponses en fin de
  chapitre dans le PDF) ;
- :mod:`.sliders` : BokehJS servi aux seules pages à curseurs statiques, image de ces figures dans le PDF ;
- :mod:`.launch_buttons` : boutons de lancement (Binder, JupyterHub, Colab) sans lien mort ;
- :mod:`.pages` : pages légères et accessibles (BokehJS à la demande, RGAA) ;
- :mod:`.formulas` : formules composées à la construction (MathJax dans node), sans MathJax dans les pages.

Ce fichier n'importe rien : charger une extension ne charge pas les autres.
"""
