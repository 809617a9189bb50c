"""`krl cell init` lists the EKI channels and RSI contexts a backup's programs open (issue 35),
with where they are opened and whether the backup holds their configuration."""

from __future__ import annotations

from interp.cellinit import cell_init

KROSHU = "kroshu__kuka-external-control-sdk/kuka_external_control_sdk/krc_setup/kss/KRC"


def test_cell_init_lists_the_network_partners(shared_corpus):
    root = shared_corpus / KROSHU
    programs = sorted(root.rglob("*.src"))
    text = cell_init(root, programs)
    lines = text.splitlines()
    eki = [x for x in lines if "EkiKSSinterface" in x]
    # the channel's name is a CHAR array of eki_communication.dat, read from the data list
    assert len(eki) == 1 and "eki_communication.src:30" in eki[0]
    rsi = [x for x in lines if x.startswith("#   rsi:")]
    assert {x.split("context ")[1].split()[0] for x in rsi} == {"rsi_gpio_joint_pos", "rsi_joint_pos"}
    assert "# network:" in text
