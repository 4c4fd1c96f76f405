import pandas as pd

from robotale.eventlog import schema


def test_csv_names_round_trip_keeps_values_and_orders_known_columns_first():
    log = pd.DataFrame(
        {
            "extra": [1],
            schema.ACTIVITY: ["takeoff"],
            schema.CASE: ["38"],
            schema.TIMESTAMP: [pd.Timestamp("2023-05-16T10:27:08.918+01:00")],
        }
    )
    short = schema.to_csv_names(log)
    assert list(short.columns) == ["case", "time", "activity", "extra"]
    back = schema.from_csv_names(short)
    assert back[log.columns].equals(log)


def test_message_roles_prefer_msg_role_then_suffix():
    log = pd.DataFrame(
        {
            schema.ACTIVITY: ["weed_position!", "weed_position?", "explore", "select", "x?"],
            schema.MSG_ROLE: [None, None, None, "send", "send"],
        }
    )
    assert schema.message_roles(log).tolist() == ["send", "receive", None, "send", "send"]
    assert schema.message_roles(log.drop(columns=schema.MSG_ROLE)).tolist() == [
        "send",
        "receive",
        None,
        None,
        "receive",
    ]
