"""Configuration des noyaux IPython de .venv (copiée par scripts/setup.sh dans .venv/etc/ipython/).

La construction du livre lance un noyau par carnet et lui parle en TCP sur 127.0.0.1 (transport par
défaut de jupyter_client). ipykernel ≥ 7 avertit alors à chaque démarrage : « Kernel is running over
TCP without encryption ». Ce trafic ne quitte pas la machine ; l'avertissement n'apprend rien et
noierait les vrais avertissements du journal. On retire ce seul message, à la source (le noyau) ;
tout autre message du noyau passe.
"""

import logging


class _DropLocalTcpNotice(logging.Filter):
    def filter(self, record: logging.LogRecord) -> bool:
        return "Kernel is running over TCP without encryption" not in record.getMessage()


logging.getLogger("IPKernelApp").addFilter(_DropLocalTcpNotice())
