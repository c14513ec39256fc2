//! The records and messages of the stream: schemas and channels (what each channel
//! carries), messages decoded by kind into [`Collected`], and the armsim metadata record;
//! the message budget is spent here.

use crate::io::record::from_ros2::{cloud_from_msg, from_msg, stamp_nanos, torque_row};
use crate::io::record::mcap_in::collected::{
    Budget, Channel, ChannelRec, Collected, Kind, SchemaRec,
};
use crate::io::record::mcap_in::cursor::Cursor;
use crate::io::record::mcap_in::record_fault::RecordFault;
use crate::io::record::mcap_out::{
    METADATA_NAME, TOPIC_COLLISIONS, TOPIC_OBSTACLES, TOPIC_ROBOT_DESCRIPTION, TOPIC_TF,
    TOPIC_TF_STATIC, TOPIC_TORQUE_CHECK,
};
use crate::io::record::message_error::MessageError;
use crate::io::record::obstacle_markers;
use crate::io::record::ros2::{self, schema_is, RosMessage};
use crate::io::record::CollisionEvent;
use mcap::records::op;

fn kind_of(schema: Option<&SchemaRec>, ch: &ChannelRec) -> Kind {
    let Some(s) = schema else {
        return Kind::Ignored;
    };
    if ch.message_encoding != ros2::MESSAGE_ENCODING {
        return Kind::Ignored;
    }
    let is = |name: &str| schema_is(&s.name, name);
    let topic = ch.topic.as_str();
    if is(ros2::JointState::NAME) {
        Kind::JointState
    } else if is(ros2::TfMessage::NAME) && topic == TOPIC_TF {
        Kind::Tf
    } else if is(ros2::TfMessage::NAME) && topic == TOPIC_TF_STATIC {
        Kind::TfStatic
    } else if is(ros2::StringMsg::NAME) && topic == TOPIC_ROBOT_DESCRIPTION {
        Kind::RobotDescription
    } else if is(ros2::PointCloud2::NAME) {
        Kind::Cloud
    } else if is(ros2::DiagnosticArray::NAME) && topic == TOPIC_TORQUE_CHECK {
        Kind::TorqueCheck
    } else if is(ros2::DiagnosticArray::NAME) && topic == TOPIC_COLLISIONS {
        Kind::Collisions
    } else if is(ros2::MarkerArray::NAME) && topic == TOPIC_OBSTACLES {
        Kind::Obstacles
    } else {
        Kind::Ignored
    }
}

/// Takes one message of `payload` bytes from the budget `b`.
fn spend(b: &mut Budget, payload: usize) -> Result<(), RecordFault> {
    b.messages = b
        .messages
        .checked_sub(1)
        .ok_or(RecordFault::TooManyMessages)?;
    b.payload = b
        .payload
        .checked_sub(payload)
        .ok_or(RecordFault::TooMuchPayload)?;
    Ok(())
}

/// An error in a record: the context when it is a message (`topic ..., message ...`), and
/// the message.
pub(super) type RecErr = (Option<String>, RecordFault);

impl Collected {
    pub(super) fn record(&mut self, opcode: u8, data: &[u8]) -> Result<(), RecErr> {
        let plain = |e: RecordFault| (None, e);
        let mut cur = Cursor { buf: data };
        match opcode {
            op::SCHEMA => {
                let id = cur.u16().map_err(plain)?;
                let name = cur.string().map_err(plain)?;
                let encoding = cur.string().map_err(plain)?;
                let n = cur.len32().map_err(plain)?;
                let data = cur.take(n).map_err(plain)?.to_vec();
                if id == 0 {
                    return Err(plain(RecordFault::SchemaIdZero));
                }
                let rec = SchemaRec {
                    name,
                    encoding,
                    data,
                };
                match self.schemas.get(&id) {
                    Some(old) if *old != rec => {
                        return Err(plain(RecordFault::SchemaRedefined(id)))
                    }
                    Some(_) => {}
                    None => {
                        self.schemas.insert(id, rec);
                    }
                }
            }
            op::CHANNEL => {
                let id = cur.u16().map_err(plain)?;
                let schema_id = cur.u16().map_err(plain)?;
                let topic = cur.string().map_err(plain)?;
                let message_encoding = cur.string().map_err(plain)?;
                let metadata = cur.map().map_err(plain)?;
                let rec = ChannelRec {
                    schema_id,
                    topic,
                    message_encoding,
                    metadata,
                };
                let schema = match schema_id {
                    0 => None,
                    s => Some(self.schemas.get(&s).ok_or_else(|| {
                        plain(RecordFault::UnknownSchema {
                            topic: rec.topic.clone(),
                            schema: s,
                        })
                    })?),
                };
                match self.channels.get(&id) {
                    Some(old) if old.rec != rec => {
                        return Err(plain(RecordFault::ChannelRedefined(id)))
                    }
                    Some(_) => {}
                    None => {
                        let kind = kind_of(schema, &rec);
                        self.channels.insert(
                            id,
                            Channel {
                                rec,
                                kind,
                                count: 0,
                            },
                        );
                    }
                }
            }
            op::MESSAGE => {
                let channel_id = cur.u16().map_err(plain)?;
                let _sequence = cur.u32().map_err(plain)?;
                let _log_time = cur.u64().map_err(plain)?;
                let _publish_time = cur.u64().map_err(plain)?;
                if let Some(b) = self.budget.as_mut() {
                    spend(b, cur.buf.len()).map_err(plain)?;
                }
                let ch = self
                    .channels
                    .get_mut(&channel_id)
                    .ok_or_else(|| plain(RecordFault::UnknownChannel(channel_id)))?;
                let index = ch.count;
                ch.count += 1;
                let (kind, topic) = (ch.kind, ch.rec.topic.clone());
                self.message(kind, &topic, cur.buf)
                    .map_err(|e| (Some(format!("topic '{topic}', message {index}")), e.into()))?;
            }
            op::METADATA => {
                let name = cur.string().map_err(plain)?;
                let map = cur.map().map_err(plain)?;
                if name == METADATA_NAME {
                    self.metadata = Some(map);
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn message(&mut self, kind: Kind, topic: &str, data: &[u8]) -> Result<(), MessageError> {
        fn dec<M: RosMessage>(data: &[u8]) -> Result<M, MessageError> {
            ros2::decode::<M>(data).map_err(|source| MessageError::Decode {
                message_type: M::NAME,
                source,
            })
        }
        match kind {
            Kind::Ignored => {}
            Kind::JointState => {
                let m: ros2::JointState = dec(data)?;
                let n = m.name.len();
                if m.position.len() != n {
                    return Err(MessageError::JointArrays {
                        count: m.position.len(),
                        what: "positions",
                        names: n,
                    });
                }
                for (what, v) in [("velocities", &m.velocity), ("efforts", &m.effort)] {
                    if !v.is_empty() && v.len() != n {
                        return Err(MessageError::JointArrays {
                            count: v.len(),
                            what,
                            names: n,
                        });
                    }
                }
                stamp_nanos(&m.header.stamp)?;
                if !self.joint_states.contains_key(topic) {
                    self.joint_state_topics.push(topic.to_string());
                }
                self.joint_states
                    .entry(topic.to_string())
                    .or_default()
                    .push(m);
            }
            Kind::Tf | Kind::TfStatic => {
                let m: ros2::TfMessage = dec(data)?;
                for ts in m.transforms {
                    let ns = stamp_nanos(&ts.header.stamp)?;
                    let t = from_msg(ts);
                    if kind == Kind::Tf {
                        self.tf.push((ns, t));
                    } else if let Some(&k) = self.static_index.get(&t.child) {
                        self.static_tf[k] = t;
                    } else {
                        self.static_index
                            .insert(t.child.clone(), self.static_tf.len());
                        self.static_tf.push(t);
                    }
                }
            }
            Kind::RobotDescription => {
                let m: ros2::StringMsg = dec(data)?;
                self.robot_description = Some(m.data);
            }
            Kind::Cloud => {
                let m: ros2::PointCloud2 = dec(data)?;
                let ns = stamp_nanos(&m.header.stamp)?;
                self.clouds.push((ns, cloud_from_msg(&m)?));
            }
            Kind::TorqueCheck => {
                let m: ros2::DiagnosticArray = dec(data)?;
                stamp_nanos(&m.header.stamp)?;
                let rows = m
                    .status
                    .iter()
                    .map(torque_row)
                    .collect::<Result<Vec<_>, _>>()?;
                self.torque_check = Some(rows);
            }
            Kind::Collisions => {
                let m: ros2::DiagnosticArray = dec(data)?;
                let ns = stamp_nanos(&m.header.stamp)?;
                for s in &m.status {
                    let get = |k: &str| {
                        s.value(k)
                            .map(str::to_string)
                            .ok_or_else(|| MessageError::MissingValue {
                                status: s.name.clone(),
                                key: k.to_string(),
                            })
                    };
                    self.collisions.push((
                        ns,
                        CollisionEvent {
                            t: 0.0,
                            body_a: get("body_a")?,
                            body_b: get("body_b")?,
                        },
                    ));
                }
            }
            Kind::Obstacles => {
                let m: ros2::MarkerArray = dec(data)?;
                self.obstacles = Some(obstacle_markers::from_message(&m));
            }
        }
        Ok(())
    }
}
