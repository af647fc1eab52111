"""The clips each results table reports on: recorded speech whose sentence a train clip also says is set apart."""
import json

from talkingface.train import subsets


def test_a_sentence_said_twice_under_two_names_is_one_sentence():
    assert subsets.normalised("To exit the menu...") == subsets.normalised("...to exit the menu.") == "to exit the menu"
    assert subsets.normalised("Something is terribly wrong!") == subsets.normalised("something is terribly wrong")
    assert subsets.normalised("to lock the conference") != subsets.normalised("to unlock the conference")


def test_members_of_each_part():
    tts, heard, unheard = ({"source": "tts"}, {"source": "human", "sentence_heard": True},
                           {"source": "human", "sentence_heard": False})
    assert [subsets.member(r, "human_unheard") for r in (tts, heard, unheard)] == [False, False, True]
    unknown = {"source": "human", "sentence_heard": None}   # no text in its alignment: not said to be unheard
    assert subsets.member(unknown, "human") and not subsets.member(unknown, "human_unheard")
    assert [subsets.member(r, "human") for r in (tts, heard, unheard)] == [False, True, True]
    assert [subsets.member(r, "synthetic") for r in (tts, heard, unheard)] == [True, False, False]
    assert [name for name, _ in subsets.labels("val")][-1] == "human_unheard" and subsets.labels("val")[0][1] == "all val clips"


def test_sentences_read_the_alignments(tmp_path):
    class Dataset:
        root = tmp_path

        def keys(self, split):
            return {"train": ["a", "b"], "test": ["c"]}[split]
    assert subsets.sentences(Dataset(), "train") == {}  # a dataset without alignments (VOCASET) has none
    (tmp_path / "alignments").mkdir()
    (tmp_path / "alignments" / "a.json").write_text(json.dumps({"text": "To exit the menu...", "phones": []}))
    (tmp_path / "alignments" / "b.json").write_text(json.dumps({"phones": []}))
    assert subsets.sentences(Dataset(), "train") == {"a": "to exit the menu"}
