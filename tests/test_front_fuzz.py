"""Every parser, fed arbitrary text, either returns a well-formed spec or raises MlcError
with a file:line location -- never another exception."""
import re

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mlc.errors import MlcError
from mlc.front import aiger, blif, expr, pla, tt
from mlc.front.load import check_spec

ALPHABETS = {
    tt: ".inputsoutputsunlisted ab01-|#\n\n dc",
    pla: ".iolbptypefdr e01-~|#\n\n 23",
    expr: "abcf01!~&|^-><=();,*+\n #majxoruitnpdINORDEROUT",
    blif: ".modelinputsoutputsnamesendconn ab01-\\\n\n#y",
    aiger: "aag 0123456789\n\n iocxy",
}
SEEDS = {
    tt: ".inputs a b\n.outputs f\n",
    pla: ".i 2\n.o 1\n",
    expr: "f = ",
    blif: ".model m\n.inputs a b\n.outputs y\n.names a b y\n",
    aiger: "aag 3 2 0 1 1\n2\n4\n6\n",
}


@pytest.mark.parametrize("mod", list(ALPHABETS), ids=lambda m: m.__name__.rsplit(".", 1)[1])
@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_parser_never_crashes(mod, data):
    tail = data.draw(st.text(alphabet=ALPHABETS[mod], max_size=60))
    text = data.draw(st.sampled_from(["", SEEDS[mod]])) + tail
    try:
        spec = mod.parse(text, "fz")
    except MlcError as e:
        assert re.match(r"fz(:\d+){1,2}: ", str(e)), str(e)
        return
    check_spec(spec)
